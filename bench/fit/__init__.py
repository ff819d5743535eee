"""``python -m bench.fit``: the data loop's fit before (a reference commit) and now, end to end, in one run."""
