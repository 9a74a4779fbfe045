import sys, statistics
from patrolsb3.bench.env import pettingzoo_steps_per_s as f
print(sys.argv[1], round(statistics.median([f(n_agents=3, n_steps=1000, seed=s) for s in range(5)])))
