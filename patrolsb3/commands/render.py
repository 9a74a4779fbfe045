"""``patrolsb3 render``: not implemented yet (placeholder to be replaced by its owner)."""


def add_arguments(parser):
    pass


def run(args):
    raise NotImplementedError("patrolsb3 render is not implemented yet")
