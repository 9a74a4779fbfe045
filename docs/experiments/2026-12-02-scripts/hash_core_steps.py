# Usage: python hash_core_steps.py <repo root of the code to import>; run it with each clone's python and compare the printed hashes.
import sys, numpy as np, hashlib
sys.path.insert(0, sys.argv[1])
from patrolsb3.core import load_map, make_config, reset_state, step, action_mask
h=hashlib.sha256()
for m in "ABCD":
    spec=load_map(m)
    for kw in ({}, {"p_dyn_max":0.5, "init_battery":(0.02,0.2), "c_home":5.0, "fault_prob":0.001}):
        cfg=make_config(m, **kw)
        st=reset_state(spec,cfg,[1,2,3,4,5]*4,n_envs=20,seed=1)
        rng=np.random.default_rng(0)
        for t in range(400):
            mask=action_mask(spec,st)
            moves=np.argmax(rng.random(mask.shape)*mask,axis=-1)
            info=step(spec,cfg,st,moves)
            for f in ("reward","collided","collisions","swap_started","battery_failed","mean_idleness","terminated"):
                h.update(np.ascontiguousarray(getattr(info,f)).tobytes())
            h.update(st.pos.tobytes()); h.update(st.battery.tobytes())
print(h.hexdigest()[:16])
