"""``patrolsb3 train``: train a parameter-shared policy with SB3 and write its run folder."""


def add_arguments(parser):
    parser.add_argument("--map", default="A", help="map name (A..D) or map file (default A)")
    parser.add_argument("--variant", default="rl-msg", help="rl-msg | rl-no-msg | rl-intention (default rl-msg)")
    parser.add_argument("--timesteps", type=int, default=None,
                        help="total agent-steps (rows x env steps); default from the hyperparameters")
    parser.add_argument("--out", default="runs/", help="root of run folders (default runs/)")
    parser.add_argument("--algo", default=None,
                        help="MaskableRecurrentPPO (default) | MaskablePPO | RecurrentPPO")
    parser.add_argument("--seed", type=int, default=0,
                        help="seed of the environments and the networks' initial weights (default 0)")
    parser.add_argument("--run-id", default=None, help="run folder name (default <algo>_seed<seed>)")
    parser.add_argument("--resume", action="store_true", help="continue the run folder from its newest checkpoint")
    parser.add_argument("--init-from", default=None, metavar="MODEL",
                        help="start a new run from the policy weights of a checkpoint, run folder or zoo entry")
    parser.add_argument("--hyperparams", default=None, help="YAML keyed by map with a default: entry")
    parser.add_argument("--recipe", default="default",
                        help="named overrides on top of the YAML: default (its values), paper (the paper's "
                             "training as written: one whole episode per rollout, 50 minibatches), zoo-stage1, "
                             "zoo-stage2 (patrolsb3/sb3/recipes.py, docs/training.md); --set applies on top")
    parser.add_argument("--set", nargs="+", action="extend", default=[], metavar="KEY=VALUE",
                        help="override hyperparameters, e.g. n_steps=128 policy_kwargs.lstm_hidden_size=64 "
                             "env.episode_steps=1000")
    parser.add_argument("--eval-freq", type=int, default=None, help="agent-steps between evaluations (0: none)")
    parser.add_argument("--checkpoint-freq", type=int, default=None, help="agent-steps between checkpoints")
    parser.add_argument("--device", default="auto", choices=["auto", "cpu", "cuda"],
                        help="where the networks train (default auto: cuda when torch sees one, else cpu)")
    parser.add_argument("--precision", default=None, choices=["auto", "fp32", "bf16"],
                        help="what the networks compute in while training (default: the hyperparameters' "
                             "precision): bf16 mixed precision where the CPU has it (docs/training.md)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.add_argument("--verbose", type=int, default=0,
                        help="SB3's verbosity: 0 quiet (default), 1 the training statistics of every update")


def run(args):
    import sys

    from ..sb3.hyperparams import merge, parse_set
    from ..sb3.recipes import recipe
    from ..sb3.train import train
    overrides = merge(recipe(args.recipe), parse_set(args.set))
    if args.precision is not None:
        overrides["precision"] = args.precision
    run_dir = train(map=args.map, variant=args.variant, timesteps=args.timesteps, out=args.out, algo=args.algo,
                    seed=args.seed, resume=args.resume, init_from=args.init_from, hyperparams=overrides,
                    hyperparams_file=args.hyperparams, eval_freq=args.eval_freq,
                    checkpoint_freq=args.checkpoint_freq, progress_bar=not args.no_progress,
                    verbose=args.verbose, run_id=args.run_id, command="patrolsb3 " + " ".join(sys.argv[1:]),
                    device=args.device, recipe=args.recipe)
    print(f"run folder: {run_dir}")
    return 0
