"""Fleets: many roasters and years of batches in a DuckDB store, fitted per batch, watched for drift.

* :mod:`.store`: the store's schema and ``ingest`` (manifest CSV -> machines, batches, series);
* :mod:`.fitting`: ``fit_fleet``, every batch not yet fitted, in-process or on Dask, resumable;
* :mod:`.drift`: the change-point detector (self-starting CUSUM) and outlier rules;
* :mod:`.report`: per machine coefficient histories, alarms, outliers and figures;
* :mod:`.synthetic`: a seeded synthetic fleet with injected drift (labelled synthetic).
"""

from .fitting import FleetSpec, fit_fleet, fleet_spec
from .report import fleet_report
from .store import ingest, open_store

__all__ = ["FleetSpec", "fit_fleet", "fleet_report", "fleet_spec", "ingest", "open_store"]
