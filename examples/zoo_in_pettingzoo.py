"""A zoo policy and a heuristic drive the PettingZoo env: ``python examples/zoo_in_pettingzoo.py``.

Prints the paper's metrics of one episode of each and writes a GIF of the zoo policy's episode.
Thin: the agent is :class:`patrolsb3.agents.PettingZooAgent`, the loop :func:`patrolsb3.agents.play_episode`.
"""
import argparse

import patrolsb3
from patrolsb3 import strategies, zoo
from patrolsb3.agents import PettingZooAgent, play_episode
from patrolsb3.render import save_gif

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--map", default="A", help="map of the zoo entry (default A)")
    parser.add_argument("--variant", default="rl-msg", help="zoo variant (default rl-msg)")
    parser.add_argument("--heuristic", default="CR", help="heuristic to compare (default CR)")
    parser.add_argument("--agents", type=int, default=3, help="team size (default 3)")
    parser.add_argument("--steps", type=int, default=1000, help="simulator steps (default 1000)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--gif", default="zoo_in_pettingzoo.gif", help="GIF of the zoo episode")
    args = parser.parse_args()

    policy = zoo.load(args.map, args.variant)
    env = patrolsb3.parallel_env(args.map, n_agents=args.agents, episode_steps=args.steps,
                                 render_mode="rgb_array", **policy.env_settings())
    learned = play_episode(env, PettingZooAgent(policy, env), seed=args.seed, frames=True)
    plain = patrolsb3.parallel_env(args.map, n_agents=args.agents, episode_steps=args.steps, comm="none")
    heuristic = strategies.get(args.heuristic, plain.spec_map, args.agents, cfg=plain.cfg, seed=args.seed)
    baseline = play_episode(plain, PettingZooAgent(heuristic, plain), seed=args.seed)
    print(f"map {args.map}, {args.agents} agents, {args.steps} steps, seed {args.seed}")
    for name, r in ((f"zoo:{args.variant}", learned), (args.heuristic.upper(), baseline)):
        print(f"{name:>16}: AVG^h {r['avg_idleness']:.1f}  MAX^h {r['max_idleness']:.1f}  "
              f"collisions {r['collisions']:.0f}  battery failures {r['battery_failures']:.0f}")
    print(f"GIF: {save_gif(learned['frames'], args.gif)}")
