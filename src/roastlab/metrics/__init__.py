"""Roast-profile figures defined once (rate of rise, crossing times): :mod:`.profile`."""
