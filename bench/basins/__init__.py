"""python -m bench.basins: the lanes against the best scalar C, and basin maps end to end."""
