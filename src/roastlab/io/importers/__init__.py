"""Importers: real roast logs into the canonical batch (time_s, Gg_kg_s, Tgi_C, Ta_C).

* :mod:`.artisan`: Artisan ``.alog`` (Python-literal or JSON dict) and Artisan CSV export;
* :mod:`.roastime`: Aillio RoasTime JSON;
* :mod:`.mapping`: generic CSV and Parquet, and a TOML column map saying which channel is time, Ta,
  Tgi and Gg, in which units, and how to get Gg (a column, a constant to identify, or a Pitot tube,
  eq. 16).

Untrusted files are parsed as data only (JSON parsers, a token translator for Python literals), never executed.
"""

from ...model.pitot import gas_flow_pitot_kg_s
from .mapping import ColumnMap, import_log, load_map

__all__ = ["ColumnMap", "gas_flow_pitot_kg_s", "import_log", "load_map"]
