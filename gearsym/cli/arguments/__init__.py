"""What the commands share: the integration options and the one way MODEL and --set become a compiled model
(:mod:`.integration`), and the parsing of --set, --teeth and --y0 (:mod:`.settings`). Every other module of
:mod:`gearsym.cli` is a command."""
