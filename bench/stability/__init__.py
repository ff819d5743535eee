"""python -m bench.stability: a 400 x 400 stability chart against a hand-written scalar C loop of the same monodromies."""
