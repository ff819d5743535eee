"""The column names a measurement file reserves: the record label and the physical time."""
from __future__ import annotations

#: the column that labels the runs of one file
RECORD = "record"
#: the physical time, converted to the model's with a time scale
PHYSICAL_TIME = "t"
