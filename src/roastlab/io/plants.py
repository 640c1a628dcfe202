"""Plant files: a preset name or a user's PLANT.toml -> :class:`roastlab.model.plant.Plant`."""

from __future__ import annotations

from pathlib import Path

from ..model.plant import Plant, as_plant, plant_from_mapping, preset_names
from .files import read_toml


def load_plant(spec: str | Path | Plant) -> Plant:
    """Load a plant: ``spec`` is a preset name (``"120kg"``, ``"360kg"``), a TOML path or a Plant.

    >>> round(load_plant("360kg").Agm_m2, 1)
    54.4
    """
    if isinstance(spec, Plant) or str(spec) in preset_names():
        return as_plant(spec)
    path = Path(str(spec))
    if path.suffix.lower() != ".toml" and not path.exists():
        return as_plant(str(spec))  # raises: unknown preset
    return plant_from_mapping(read_toml(path), path, path.stem)
