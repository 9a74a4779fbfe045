"""One module per ``patrolsb3`` sub-command: ``add_arguments(parser)`` and ``run(args)``."""
