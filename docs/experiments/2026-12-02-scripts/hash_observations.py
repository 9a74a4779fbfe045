# Usage: python hash_observations.py <repo root>; as hash_core_steps.py, for actor observations.
import sys, numpy as np, importlib
sys.path.insert(0, sys.argv[1])
from patrolsb3.core import load_map, make_config, reset_state, step, action_mask
from patrolsb3.core.observe import actor_observation, critic_state
out=[]
for m in "ABCD":
    spec=load_map(m); cfg=make_config(m, local_idleness=True, init_battery=(0.05,0.3))
    st=reset_state(spec,cfg,[1,2,3,4,5]*4,n_envs=20,seed=1)
    rng=np.random.default_rng(0)
    for t in range(300):
        st.messages=np.where(st.active, rng.integers(0,17,st.pos.shape),0)
        g,v=actor_observation(spec,cfg,st,phase=t%2)
        out.append(g.sum()*1.0+ (g*np.arange(g.size).reshape(g.shape)%97).sum()+v.sum()+(v*np.arange(v.size).reshape(v.shape)%89).sum())
        mask=action_mask(spec,st)
        moves=np.argmax(rng.random(mask.shape)*mask,axis=-1)
        step(spec,cfg,st,moves)
print(np.float64(np.sum(out)).hex(), len(out))
