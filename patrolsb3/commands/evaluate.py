"""``patrolsb3 evaluate``: not implemented yet (placeholder to be replaced by its owner)."""


def add_arguments(parser):
    pass


def run(args):
    raise NotImplementedError("patrolsb3 evaluate is not implemented yet")
