"""``python -m bench.orbits``: the whole period-1 frequency-response curve against the brute-force sweep."""
