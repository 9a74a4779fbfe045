"""What each communication option does to the listening figure, on a tiny room (short runs).

Usage: python listening_options.py OUT [STEPS] [SEEDS] [SETTINGS]: for each setting below (or
those named, comma-separated, in SETTINGS), train rl-msg on
the 4 x 6 room ROOM (zoo-stage1 recipe: 300-step episodes, full batteries, planes messages; no
curriculum; teams 1,1,1,1,2,3,3,3 of max 3) for STEPS agent-steps (default 150,000) per seed, then
print the listening figure of the final policy (2 agents, 8 episodes x 300 steps, seed 1000) and
the mean idleness of the run's last 20 training episodes. Also the untrained policy (0 steps).
"""
import csv
import json
import sys
from pathlib import Path

from patrolsb3.listening import listening
from patrolsb3.sb3.recipes import recipe
from patrolsb3.sb3.hyperparams import merge
from patrolsb3.sb3.train import train
from patrolsb3.zoo import load_checkpoint

ROOM = "S.....\n..#...\n...5..\n......\n"
SETTINGS = {"baseline": {}, "ent_coef_message=0.01": {"ent_coef_message": 0.01},
            "signal_coef=0.05": {"signal_coef": 0.05}, "listen_coef=0.05": {"listen_coef": 0.05}, "listen_coef=0.5": {"listen_coef": 0.5},
            "listen_coef=0.5+signal_coef=0.05": {"listen_coef": 0.5, "signal_coef": 0.05},
            "message_team_share=0.5": {"message_team_share": 0.5}, "message_team_share=1": {"message_team_share": 1.0}}

out = Path(sys.argv[1])
steps = int(sys.argv[2]) if len(sys.argv) > 2 else 150_000
seeds = range(int(sys.argv[3]) if len(sys.argv) > 3 else 1)
if len(sys.argv) > 4:
    SETTINGS = {name: SETTINGS[name] for name in sys.argv[4].split(",")}
out.mkdir(parents=True, exist_ok=True)
room = out / "room.txt"
room.write_text(ROOM)
rows = []
for name, extra in SETTINGS.items():
    for seed in seeds:
        hp = merge(recipe("zoo-stage1"), {"curriculum": False, "n_steps": 64, "batch_size": 1024,
                                          "env": {"max_agents": 3}, **extra})
        run = out / "room" / "rl-msg" / f"{name}_seed{seed}"
        if not (run / "model.zip").is_file():      # a rerun keeps the finished runs
            run = train(map=str(room), variant="rl-msg", timesteps=steps, out=out, seed=seed,
                        run_id=f"{name}_seed{seed}", hyperparams=hp, eval_freq=0, progress_bar=False,
                        checkpoint_freq=10**9, device="cpu")
        figure = listening(load_checkpoint(run / "model.zip"), n_agents=2, episodes=8, steps=300, seed=1000)
        with open(run / "curve.csv") as f:
            idleness = [float(r["mean_idleness"]) for r in csv.DictReader(f)][-20:]
        rows.append({"setting": name, "seed": seed, **{k: figure[k] for k in (
            "kl_nats", "greedy_changed", "symbols_used", "symbol_entropy_bits", "mi_own_move_bits",
            "mi_others_moves_bits")}, "train_mean_idleness_last20": sum(idleness) / max(len(idleness), 1)})
        print(json.dumps(rows[-1]), flush=True)
keys = list(rows[0])
print("| " + " | ".join(keys) + " |\n|" + " --- |" * len(keys))
for r in rows:
    print("| " + " | ".join(f"{v:.3f}" if isinstance(v, float) else str(v) for v in r.values()) + " |")
