"""``patrolsb3 compare``: not implemented yet (placeholder to be replaced by its owner)."""


def add_arguments(parser):
    pass


def run(args):
    raise NotImplementedError("patrolsb3 compare is not implemented yet")
