"""``patrolsb3 render --map A --agents 3 --steps 300 --out run.gif [--strategy NAME|zoo:VARIANT] [--seed S]``:
run one episode of a heuristic on the batched core (n_envs = 1) and write it as a GIF."""

from ..core import load_map, make_config, reset_state, step
from ..evaluate import load_policy
from ..outputs import check_output_file


def add_arguments(parser):
    parser.add_argument("--map", default="A", help="shipped map name or .txt path (default A)")
    parser.add_argument("--agents", type=int, default=3, help="team size (default 3)")
    parser.add_argument("--steps", type=int, default=300, help="simulator steps (default 300)")
    parser.add_argument("--out", default="run.gif", help="output GIF (default run.gif)")
    parser.add_argument("--strategy", default="RANDOM",
                        help="RANDOM, CR, PART, SEBS, CYCLIC or a zoo model zoo:<variant> (default RANDOM)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the episode and the strategy")
    parser.add_argument("--fps", type=float, default=10.0, help="frames per second of the GIF")
    parser.add_argument("--every", type=int, default=1, help="keep one frame every N steps")
    parser.add_argument("--tile", type=int, default=32, help="pixels per cell")
    parser.add_argument("--frame", metavar="PNG", help="also write the last frame as a PNG")


def run(args):
    from pathlib import Path

    from PIL import Image

    from ..render import render_frame, save_gif
    if args.steps < 1 or args.every < 1 or args.tile < 4:
        raise ValueError("--steps and --every must be >= 1 and --tile >= 4")
    map_file = [args.map] if Path(args.map).is_file() else []        # a map file is an input
    check_output_file(args.out, "--out", inputs=map_file)
    if args.frame:
        check_output_file(args.frame, "--frame", inputs=map_file)
    spec = load_map(args.map)
    cfg = make_config(spec.name, episode_steps=max(5000, args.steps))
    state = reset_state(spec, cfg, args.agents, n_envs=1, seed=args.seed)
    policy = load_policy(args.strategy, spec, args.agents, cfg, seed=args.seed)
    memory, totals = None, {"collisions": 0, "swaps": 0, "failures": 0, "frames": 0}
    last = {}

    def frames():                     # one frame at a time: a long episode is never held whole
        nonlocal memory
        yield render_frame(spec, cfg, state, tile=args.tile)
        for t in range(1, args.steps + 1):
            actions, memory = policy.predict(state, memory)                   # (1, A, 2)
            info = step(spec, cfg, state, actions[..., 1], messages=actions[..., 0],
                        compute_reward=False)
            totals["collisions"] += int(info.collisions.sum())
            totals["swaps"] += int(info.swap_started.sum())
            totals["failures"] += int((info.battery_failed | info.fault_failed).sum())
            if t % args.every == 0 or info.terminated[0]:
                yield render_frame(spec, cfg, state, tile=args.tile)
            if info.terminated[0]:
                print(f"every agent failed at step {t}; the animation stops there")
                break

    def counted(stream):
        for frame in stream:
            totals["frames"] += 1
            last["frame"] = frame
            yield frame

    path = save_gif(counted(frames()), args.out, fps=args.fps)
    print(f"wrote {path} ({totals['frames']} frames, {Path(path).stat().st_size // 1024} kB): "
          f"map {spec.name}, {args.agents} agents, {args.strategy.upper()}, seed {args.seed}, "
          f"{int(state.t[0])} steps, mean idleness {state.idle[0].mean():.1f}, "
          f"{totals['collisions']} collisions, {totals['swaps']} swaps, {totals['failures']} failures")
    if args.frame:
        Path(args.frame).parent.mkdir(parents=True, exist_ok=True)
        Image.fromarray(last["frame"]).save(args.frame, optimize=True)
        print(f"wrote {args.frame}")
    return 0
