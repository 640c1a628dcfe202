"""The roaster's page: ``roastlab app`` (a local web page over the library; :mod:`.server`)."""
