#!/usr/bin/env bash
# How the zoo was made (run from the repository root), on the 2-core development machine with
# every run side by side (one torch thread each). Settings and why: zoo/README.md.
# Since 2026-12-03 these entries (behind the return guard) live in zoo/guarded/; the paths below say so.
#
# Stage 1 (patrol only). This time A's three runs were started ten minutes before B, C and D,
# and stopped at their 1,250,000-step checkpoints (~63 min wall, 0.37-0.39 CPU h each); B, C
# and D ran 2,700 s (788,480 steps, 0.21 CPU h each).
# Stage 2 (patrol + recharge, from the stage-1 weights): 3,300 s for all six (A/rl-no-msg
# started a minute later, 3,210 s).
#
# B, C and D v4 (2026-12-01): the three stages of zoo/train_stages.sh, three runs side by side,
#   export STAGE1_OUT=runs/v5_stage1 STAGE2_OUT=runs/v5_zoo STAGE3_OUT=runs/v5_stage3
#   export STAGE1_RUNS="B:rl-msg C:rl-msg D:rl-msg" ZOO_RUNS="B:rl-msg C:rl-msg D:rl-msg"
#   TIMESTEPS=1500000 zoo/train_stages.sh 1 2400
#   TIMESTEPS=2000000 zoo/train_stages.sh 2 3000
#   TIMESTEPS=800000 zoo/train_stages.sh 3 1500
# (each ran to its step budget), every drill checkpoint validated with
#   patrolsb3 zoo validate runs/v5_stage3/<map>/rl-msg/MaskableRecurrentPPO_seed0
# and the best exported with --cpu-hours = stage 1 (ps, 0.26) + stage 2 and 3 (their
# cpu_time.csv, stage 3 up to the checkpoint), --episodes 10 --steps 14400 --seed 0, the
# stage-1/2 curves, commands and stage 2's cpu_time.csv copied beside it.
# B and D v6 (2026-12-01, later that day): stage 2h of zoo/train_stages.sh from the v4
# stage-1 weights (runs/v5_stage1), run by hand with the same settings:
#   STAGE1_OUT=runs/v5_stage1 STAGE2H_OUT=runs/v6_home TIMESTEPS=2700000 zoo/train_stages.sh 2h 6000
# (run ids ent0.002 instead of MaskableRecurrentPPO_seed0; B ran to 1.5 M, was resumed to
# 2.7 M and then 4.0 M; D ran to 2.7 M), every checkpoint validated with
#   patrolsb3 zoo validate runs/v6_home/<map>/rl-msg/ent0.002
# the best ones cross-checked greedy on 8 episodes x 3,000 steps, n = 1, 3, 5, seed 11, and
# the chosen one exported (B 1,805,280, D 1,100,000) with --cpu-hours = stage 1 (ps, 0.26) +
# this run's cpu_time.csv up to the checkpoint (B 0.34, D 0.20); v4's stage-2 files removed
# from the entries (the v4 entries are in the git history), the sampled evaluation and the
# comparison as for A v5 below.
# A, B and D rl-msg v7 (2026-12-01, evening): stage g of zoo/train_stages.sh (long episodes
# behind the return guard env.return_guard=true), three runs side by side, 6,000 s each (they
# stopped at their 4 M step budget), then resumed to 6.5 M (stopped once on the way to take
# the guard's final rule, zoo/README.md):
#   STAGE1_OUT=runs/v5_stage1 ZOO_RUNS="B:rl-msg D:rl-msg" zoo/train_stages.sh g 6000
#   STAGEG_FROM="zoo/{map}/{variant}" ZOO_RUNS="A:rl-msg" zoo/train_stages.sh g 6000   # from A's v5
#   STAGE1_OUT=runs/v5_stage1 ZOO_RUNS="A:rl-msg B:rl-msg D:rl-msg" TIMESTEPS=6500000 \
#     zoo/train_stages.sh g 2640 --resume            # and again with 1900 s
# the newest six checkpoints of each validated with
#   patrolsb3 zoo validate runs/stageg/<map>/rl-msg/MaskableRecurrentPPO_seed0 --last 6
# and the best exported with --episodes 10 --steps 14400 --seed 0 (A: CPU hours measured along
# the chain; B and D: --cpu-hours = stage 1 (ps, 0.26) + this run's cpu_time.csv up to the
# checkpoint), B and D's stage-1 curve and command kept beside; the sampled evaluation and the
# comparison as for A v5 below.
# A/rl-no-msg, A/rl-intention and C/rl-msg v7 (2026-12-01, night): stage g too, three runs
# side by side (stopped near 0.6 M when the machine went, resumed from the 500 k checkpoints):
#   STAGEG_FROM="zoo/{map}/{variant}" ZOO_RUNS="A:rl-no-msg A:rl-intention" TIMESTEPS=6500000 \
#     zoo/train_stages.sh g 7200                     # then again with 6800 --resume
#   STAGE1_OUT=runs/v5_stage1 ZOO_RUNS="C:rl-msg" TIMESTEPS=6500000 zoo/train_stages.sh g 7200
#                                                    # then again with 6800 --resume
# (each reached its 6.5 M step budget), validated and exported as A, B and D's v7 (the best:
# A/rl-no-msg 5,500,000, A/rl-intention 6,500,640, C 6,000,000; C with --cpu-hours = stage 1
# (ps, 0.26) + this run's cpu_time.csv up to the checkpoint, 0.96), A's earlier command.txt
# and curve.csv renamed *_stage3 (rl-no-msg) and *_stage4 (rl-intention), C's v4 stage-2/3
# files removed (git history); the sampled evaluation and the comparison as for A v5 below.
# B, C and D rl-no-msg v7 (2026-12-02): stage 1 and stage g as their rl-msg, three runs side
# by side (stage g stopped by time at 1.93 M and 6.30 M, resumed with --resume each time):
#   STAGE1_OUT=runs/v5_stage1 STAGE1_RUNS="B:rl-no-msg C:rl-no-msg D:rl-no-msg" \
#     TIMESTEPS=1500000 zoo/train_stages.sh 1 2700
#   STAGE1_OUT=runs/v5_stage1 ZOO_RUNS="B:rl-no-msg C:rl-no-msg D:rl-no-msg" TIMESTEPS=6500000 \
#     zoo/train_stages.sh g 2100                     # then 4500 --resume, then 900 --resume
# validated and exported as A, B and D's v7 (the best: B 6,502,400, C 6,175,120, D 5,675,120;
# CPU hours measured along the chain, stage 1 included), the stage-1 curve and command copied
# beside as curve_stage1.csv / command_stage1.txt; the sampled evaluation and the comparison
# as for A v5 below.
# B, C and D rl-intention v7 (2026-12-02): the same, three runs side by side (stage g stopped
# by time at about 2.5 M, resumed with --resume):
#   STAGE1_OUT=runs/v5_stage1 STAGE1_RUNS="B:rl-intention C:rl-intention D:rl-intention" \
#     TIMESTEPS=1500000 zoo/train_stages.sh 1 3000
#   STAGE1_OUT=runs/v5_stage1 ZOO_RUNS="B:rl-intention C:rl-intention D:rl-intention" \
#     TIMESTEPS=6500000 zoo/train_stages.sh g 2880   # then 4800 --resume
# validated and exported as above (the best: B 6,502,360, C 5,498,840, D 5,990,680), the
# stage-1 curve and command beside; the sampled evaluation and the comparison as for A v5 below.
# A v5 (rl-msg, rl-intention; rl-no-msg keeps v4): stage 4 from the v4 entries,
#   ZOO_RUNS="A:rl-msg" TIMESTEPS=1228800 STAGE4_OUT=runs/mix zoo/train_stages.sh 4 5400
#   ZOO_RUNS="A:rl-no-msg A:rl-intention" STAGE4_OUT=runs/mix zoo/train_stages.sh 4 3000
# (the same commands as these, run by hand), validated the same way, the best exported with
#   patrolsb3 zoo export runs/mix/A/<variant>/MaskableRecurrentPPO_seed0 --checkpoint <best> \
#     --zoo-dir runs/zoo_mix --episodes 10 --steps 14400 --seed 0     # CPU hours measured
# and copied into zoo/A/<variant> (the v4 stage-3 curve and command renamed *_stage3); the
# sampled evaluation: patrolsb3.zoo.write_eval(copy, steps=3600, deterministic=False) on a
# scratch copy, eval_sampled.json copied beside; the comparison as at the end of this script
# (its heuristics reused from zoo/comparison/results.json).
#
# v4 (map A only; B, C and D were v2 then): the v3 entries below, then stage 3 of
# zoo/train_stages.sh (the recharge drill), three runs side by side, started from the v3 zoo
# entries (zoo/A/<variant>, now kept as curve_stage2.csv / command_stage2.txt) and run to
# 614,400 agent-steps, then resumed to 1,228,800 (command.txt has both calls; rl-no-msg's
# first 613,040 steps ran as a trial, runs/drill/.../d1_cd200, with the same settings, and its
# folder was moved into runs/v4_stage3), every checkpoint from 614,400 on validated with
#   patrolsb3 zoo validate runs/v4_stage3/A/<variant>/MaskableRecurrentPPO_seed0
# (4 episodes x 3,000 steps for n = 1, 3, 5, seed 7) and the best exported:
#   patrolsb3 zoo export runs/v4_stage3/A/<variant>/MaskableRecurrentPPO_seed0 \
#     --checkpoint .../checkpoints/model_<best>_steps.zip --cpu-hours <v3 + stage 3> \
#     --episodes 10 --steps 14400 --seed 0
# with the v3 curves and commands copied beside (curve_stage1.csv, curve_stage2.csv, ...);
# the checkpoints, CPU hours and validation figures are in zoo/README.md; then the sampled
# evaluation and the comparisons as at the end of this script.
#
# v3 (map A; replaced by v4): zoo/train_stages.sh stages 1 and 2
# (local idleness, c_d = 200), three runs side by side, stage 1 stopped by time (2,100 s),
# stage 2 by SIGINT after 63 minutes; then exported with their CPU hours and evaluated
# (deterministic 24 h into zoo/A, sampled 6 h as eval_sampled.json):
#   STAGE1_OUT=runs/v3_stage1 STAGE1_RUNS="A:rl-msg A:rl-no-msg A:rl-intention" zoo/train_stages.sh 1 2100
#   STAGE1_OUT=runs/v3_stage1 STAGE2_OUT=runs/v3_zoo ZOO_RUNS="A:rl-msg A:rl-no-msg A:rl-intention" \
#     zoo/train_stages.sh 2 4200      # stopped at 63 min
#   CPU hours (ps, both stages): rl-msg 0.99, rl-no-msg 0.99, rl-intention 1.01; export and
#   evaluation as in the loop below with runs/v3_zoo and runs/v3_stage1 in place of runs/zoo
#   and runs/stage1.
#
# v2 (B, C, D, and A's earlier entries), with the script (then train_two_stage.sh) before c_d
# and the local idleness were added to it (git history, commit 0519976):
set -euo pipefail
zoo/train_stages.sh 1 2700
zoo/train_stages.sh 2 3300
# Export (policy only) with the CPU hours of both stages (CPU_HOURS: "A:rl-msg=0.8 ..."), the
# stage-1 learning curve and command beside the stage-2 ones, and eval.json (10 episodes x
# 14,400 steps for n = 1..5, seed 0, deterministic actions).
rm -rf zoo/guarded/A zoo/guarded/B zoo/guarded/C zoo/guarded/D
CPU_HOURS=${CPU_HOURS:-"A:rl-msg=0.65 A:rl-no-msg=0.66 A:rl-intention=0.65 B:rl-msg=0.50 C:rl-msg=0.50 D:rl-msg=0.50"}
for entry in $CPU_HOURS; do
  run=${entry%%=*}; map=${run%%:*}; variant=${run#*:}
  ( patrolsb3 zoo export "runs/zoo/$map/$variant/MaskableRecurrentPPO_seed0" --cpu-hours "${entry#*=}" \
      --episodes 10 --steps 14400 --seed 0 > "runs/logs/export_${map}_${variant}.log" 2>&1
    cp "runs/stage1/$map/$variant/MaskableRecurrentPPO_seed0/curve.csv" "zoo/guarded/$map/$variant/curve_stage1.csv"
    cp "runs/stage1/$map/$variant/MaskableRecurrentPPO_seed0/command.txt" "zoo/guarded/$map/$variant/command_stage1.txt" ) &
done
wait
patrolsb3 compare --maps A,B,C,D --agents 1-5 --episodes 10 --steps 14400 --seed 0 --out zoo/guarded/comparison
# the same models sampling their actions (--stochastic; 6 h episodes, for time): eval_sampled.json beside eval.json,
# and their tables in zoo/guarded/comparison_sampled (zoo models only; the heuristics are above)
for entry in $CPU_HOURS; do
  run=${entry%%=*}; map=${run%%:*}; variant=${run#*:}
  ( patrolsb3 zoo export "runs/zoo/$map/$variant/MaskableRecurrentPPO_seed0" --zoo-dir runs/zoo_sampled \
      --stochastic --episodes 10 --steps 3600 --seed 0 > "runs/logs/sampled_${map}_${variant}.log" 2>&1
    cp "runs/zoo_sampled/guarded/$map/$variant/eval.json" "zoo/guarded/$map/$variant/eval_sampled.json" ) &
done
wait
python -c "
import glob, json
from patrolsb3.report import write_compare
results = [r for f in sorted(glob.glob('zoo/guarded/*/*/eval_sampled.json')) for r in json.load(open(f))['results']]
write_compare(results, 'zoo/guarded/comparison_sampled')"
