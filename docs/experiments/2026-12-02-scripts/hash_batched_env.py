# Usage: python hash_batched_env.py <repo root>: hash of what the training env (BatchedPatrolEnv) returns
# over seeded random legal actions: 8 episodes with two settings (a mix), learned messages, planes.
import sys, hashlib, numpy as np
sys.path.insert(0, sys.argv[1])
from patrolsb3.core import load_map, make_config
from patrolsb3.sb3.batched_env import BatchedPatrolEnv
h = hashlib.sha256()
spec = load_map("A")
for kw in ({"message_encoding": "planes", "local_idleness": True}, {"comm": "none"}, {"comm": "intention", "return_guard": True}):
    long = make_config("A", episode_steps=150, init_battery=(0.05, 1.0), **kw)
    short = make_config("A", episode_steps=40, init_battery=(0.05, 0.3), **kw)
    env = BatchedPatrolEnv(spec, [short, long] * 4, [1, 2, 3, 5, 1, 4, 2, 3])
    obs, infos = env.reset(seed=3)
    rng = np.random.default_rng(0)
    for t in range(700):
        acts = {}
        for a in env.possible_agents:
            m = infos[a]["action_mask"]; n = long.n_symbols
            acts[a] = (int(np.argmax(rng.random(n) * m[:n])), int(np.argmax(rng.random(5) * m[n:])))
        obs, rew, te, tr, infos = env.step(acts)
        for a in env.possible_agents:
            h.update(obs[a].tobytes()); h.update(repr((rew[a], te[a], tr[a])).encode())
            for k, v in infos[a].items():
                h.update(k.encode()); h.update(repr(v).encode() if not isinstance(v, np.ndarray) else v.tobytes())
print(h.hexdigest()[:16])
