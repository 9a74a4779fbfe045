# Usage: python hash_env.py <repo root>: a hash of everything the PettingZoo env returns (observation
# bytes, rewards, terminations, truncations, every info value) over seeded random legal actions, for
# several settings; run with two clones and compare the printed hashes.
import sys, hashlib, numpy as np
sys.path.insert(0, sys.argv[1])
from patrolsb3.env import parallel_env
h = hashlib.sha256()
settings = [("A", 3, {}), ("B", 5, {"message_encoding": "planes", "local_idleness": True}),
            ("C", 4, {"comm": "intention"}), ("D", 2, {"comm": "none", "return_guard": True}),
            ("A", 5, {"message_encoding": "planes", "p_dyn_max": 0.5, "init_battery": (0.02, 0.2),
                      "c_home": 5.0, "fault_prob": 0.001, "episode_steps": 300}),
            ("C", 3, {"comm": "learned", "message_timing": "delayed"})]
for map_name, k, kw in settings:
    env = parallel_env(map_name, n_agents=k, **kw)
    rng = np.random.default_rng(0)
    for episode in range(2):
        obs, infos = env.reset(seed=episode)
        for t in range(800):
            if not env.agents:
                break
            actions = {}
            for a in env.agents:
                mm, vm = infos[a]["action_mask"]
                actions[a] = (int(np.argmax(rng.random(mm.shape) * mm)), int(np.argmax(rng.random(vm.shape) * vm)))
            obs, rew, term, trunc, infos = env.step(actions)
            for a in sorted(obs):
                for part in ("grid", "vector", "critic"):
                    h.update(np.ascontiguousarray(obs[a][part]).tobytes())
                h.update(repr((rew[a], term[a], trunc[a])).encode())
                for key, value in infos[a].items():
                    h.update(key.encode())
                    if isinstance(value, tuple):
                        for v in value: h.update(np.asarray(v).tobytes())
                    else:
                        h.update(np.asarray(value).tobytes() + repr(type(value)).encode())
print(h.hexdigest()[:16])
