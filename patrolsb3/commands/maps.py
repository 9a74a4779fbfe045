"""``patrolsb3 maps``: not implemented yet (placeholder to be replaced by its owner)."""


def add_arguments(parser):
    pass


def run(args):
    raise NotImplementedError("patrolsb3 maps is not implemented yet")
