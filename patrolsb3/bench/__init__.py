"""Speed benchmarks behind ``patrolsb3 bench``; each module has ``run(repeats, quick) -> dict``."""
