"""``sensorplan`` command line (also ``python -m agents``): ``train``, ``evaluate``,
``benchmark``, ``demo``, ``convert``, ``view`` and ``record``.

    sensorplan train --env sensorplan/Navigate-v0 --algo ppo --timesteps 150000 --seed 0 --n-envs 2
    sensorplan evaluate --env sensorplan/Navigate-v0 --policies oracle random \\
        agents/pretrained/ppo_navigate_lab.zip --episodes 200 --seed 0
    sensorplan train --backend rllib [--address ADDR]
        (watchers, RLlib; agents.learning.rllib_train)
    sensorplan evaluate ... --backend ray [--address ADDR]   (episodes on Ray workers)
    sensorplan demo            (the paper's surveillance scenario end to end; see agents.demo)
    sensorplan convert plan.geojson scene.json   (GeoJSON / WKT / scene JSON, by extension,
                                                  or a bundled name as input: convert lab
                                                  lab.geojson; see geometry.formats)
    sensorplan dataset record --env ID --episodes N --dataset-id ns/name-v0   (oracle demos,
                                Minari; see agents.learning.dataset)
    sensorplan imitate --env ID --method bc|dagger|dagger+ppo   (learning from the oracle;
                                see agents.learning.imitation)
    sensorplan view lab        (scenes and exact regions in the browser; --export view.html
                                writes one self-contained file; see sensorplan_gym.viewer)
    sensorplan record --policy oracle --out ep.json   (one episode for sensorplan view
                                                        --rollout ep.json)
"""

from __future__ import annotations

import argparse
import json
import sys

from .checks import EXTRA_OF_MODULE, check_writable_file, missing_extra_message

__all__ = ["EXTRA_OF_MODULE", "build_parser", "main"]

ENV_CHOICES_HELP = "sensorplan/Placement-v0, sensorplan/Navigate-v0 or sensorplan/Recognize-v0"
POLICIES_HELP = (
    "'oracle', 'random', 'hint-rule' (Navigate-v0 and Recognize-v0: a fixed controller on the "
    "view_hint, aim_features and evidence observations), 'hint-rule-turn' (Recognize-v0, on "
    "view_hint with hint_aim=False) and/or paths to model zips or pixel policies (.pt)"
)


def _json_dict(text: str) -> dict:
    try:
        value = json.loads(text)
    except json.JSONDecodeError as e:
        raise argparse.ArgumentTypeError(f"not valid JSON: {e}") from None
    if not isinstance(value, dict):
        raise argparse.ArgumentTypeError(f"expected a JSON object, got {text!r}")
    return value


def build_parser() -> argparse.ArgumentParser:
    from .learning.policies import ALGOS

    parser = argparse.ArgumentParser(
        prog="sensorplan",
        description="Sensor planning (Briggs & Donald): train and evaluate agents, run the demo.",
    )
    sub = parser.add_subparsers(
        dest="command",
        metavar="{train,evaluate,benchmark,demo,convert,view,record,dataset,imitate}",
    )
    sub.required = True

    t = sub.add_parser(
        "train",
        help="train a stable-baselines3 baseline",
        description="Train an SB3 agent with the YAML hyperparameters in "
        "agents/configs/<algo>.yaml (command-line values override).",
    )
    t.add_argument("--env", default=None, help=ENV_CHOICES_HELP + " (required with --backend sb3)")
    t.add_argument("--algo", default=None, choices=ALGOS, help="required with --backend sb3")
    t.add_argument(
        "--backend",
        choices=("sb3", "rllib"),
        default="sb3",
        help="sb3: a stable-baselines3 baseline (default); rllib: multi-agent PPO with a "
        "shared policy on the watch task (sensorplan_gym.watch_v0) with Ray RLlib, config "
        "agents/configs/rllib_watch.yaml (see agents.learning.rllib_train)",
    )
    t.add_argument(
        "--address",
        default=None,
        help="rllib: attach to this Ray cluster ('auto', 'ray://head:10001') instead of "
        "starting a local Ray instance",
    )
    t.add_argument(
        "--iterations", type=int, default=None, help="rllib: training iterations (default: config)"
    )
    t.add_argument(
        "--timesteps",
        type=int,
        default=None,
        help="total environment steps (default: n_timesteps from the config)",
    )
    t.add_argument("--seed", type=int, default=0)
    t.add_argument(
        "--seeds",
        type=int,
        nargs="+",
        default=None,
        help="train once per seed, one after the other (outputs <out>_s<seed>)",
    )
    t.add_argument(
        "--hp",
        nargs="+",
        default=None,
        metavar="KEY=VALUE",
        help="hyperparameter overrides, values in YAML, e.g. --hp n_steps=64 learning_rate=1e-4",
    )
    t.add_argument(
        "--checkpoint-freq", type=int, default=None, help="save a checkpoint every N env steps"
    )
    t.add_argument("--resume", default=None, help="continue training from this model zip")
    t.add_argument(
        "--n-envs", type=int, default=None, help="parallel envs (default: n_envs from the config)"
    )
    t.add_argument(
        "--env-kwargs",
        type=_json_dict,
        default=None,
        help='JSON gym.make kwargs merged over the config\'s, e.g. \'{"scene": "lab"}\'',
    )
    t.add_argument(
        "--config", default=None, help="hyperparameter YAML (default agents/configs/<algo>.yaml)"
    )
    t.add_argument("--out", default=None, help="output folder (default runs/<algo>_<env>_s<seed>)")
    t.add_argument(
        "--eval-freq",
        type=int,
        default=None,
        help="env steps between periodic evaluations (default: from the config)",
    )
    t.add_argument("--eval-episodes", type=int, default=None)
    t.add_argument(
        "--vec-env",
        choices=("batched", "auto", "subproc", "dummy"),
        default=None,
        help="batched (= auto): all envs in one native vector env of the batched core; "
        "dummy/subproc: SB3's DummyVecEnv/SubprocVecEnv of single envs "
        "(default: the config's vec_env, else batched)",
    )
    t.add_argument(
        "--threads", type=int, default=1, help="torch threads (default 1; 0 keeps torch's default)"
    )
    t.add_argument("--no-progress", action="store_true", help="no progress bar")
    t.add_argument("--no-tensorboard", action="store_true", help="no TensorBoard logs")

    e = sub.add_parser(
        "evaluate",
        help="evaluate oracle / random / trained policies",
        description="Evaluate policies on the same episode seeds "
        "(1_000_000 + seed onwards) and write a table, JSON, CSV "
        "and a PNG plot.",
    )
    e.add_argument("--env", required=True, help=ENV_CHOICES_HELP)
    e.add_argument("--policies", nargs="+", required=True, help=POLICIES_HELP)
    e.add_argument("--episodes", type=int, default=100)
    e.add_argument("--seed", type=int, default=0)
    e.add_argument(
        "--env-kwargs",
        type=_json_dict,
        default=None,
        help="JSON gym.make kwargs for the evaluation env",
    )
    e.add_argument(
        "--out",
        default=None,
        help="output folder (default runs/eval_<env>_s<seed>; .2, .3, ... appended when it exists)",
    )
    e.add_argument("--no-plot", action="store_true")
    e.add_argument(
        "--backend",
        choices=("local", "ray"),
        default="local",
        help="ray: play the episodes on Ray workers (same results as local; "
        "agents.evaluation.ray_eval)",
    )
    e.add_argument("--address", default=None, help="ray: an existing Ray cluster's address")
    e.add_argument(
        "--stochastic",
        action="store_true",
        help="trained models sample their actions (default: deterministic)",
    )

    bm = sub.add_parser(
        "benchmark",
        help="evaluate policies on the train / test / bundled-scene splits "
        "(agents.evaluation.benchmark)",
        description="Every policy on procedural train and held-out test scenes and on every "
        "bundled scene, with the difficulty knob reported; writes benchmark.json/.csv.",
    )
    bm.add_argument("--env", required=True, help=ENV_CHOICES_HELP)
    bm.add_argument("--policies", nargs="+", required=True, help=POLICIES_HELP)
    bm.add_argument("--episodes", type=int, default=100)
    bm.add_argument("--seed", type=int, default=0)
    bm.add_argument(
        "--difficulty",
        type=float,
        default=None,
        help="min_start_distance of the procedural splits, in scene diameters (default 0.35, "
        "or the --level's)",
    )
    bm.add_argument(
        "--level",
        choices=("easy", "medium", "hard"),
        default=None,
        help="draw the procedural splits from this benchmark level's scene family "
        "(geometry.families.DIFFICULTIES; default: the plain random-scene generator)",
    )
    bm.add_argument(
        "--splits",
        nargs="+",
        default=None,
        help="train, test, ood, ood:<scene>, real, real:<map>, narrow (the bundled scenes "
        "and real maps with a 60-90 degree sensor), narrow:<scene or map> "
        "(default: train test ood)",
    )
    bm.add_argument("--env-kwargs", type=_json_dict, default=None)
    bm.add_argument(
        "--out",
        default=None,
        help="output folder (default runs/benchmark_<env>; .2, .3, ... appended when it exists)",
    )
    bm.add_argument(
        "--stochastic",
        action="store_true",
        help="trained models sample their actions (default: deterministic)",
    )

    sub.add_parser(
        "demo", help="the paper's surveillance scenario end to end (agents.demo)", add_help=False
    )
    sub.add_parser(
        "view",
        help="scenes and exact regions in the browser, live or exported to HTML "
        '(needs the "viewer" extra; sensorplan view --help)',
        add_help=False,
    )

    c = sub.add_parser(
        "convert",
        help="convert a map between scene JSON, GeoJSON and WKT",
        description="Convert a scene: the format follows each file's extension -- .json "
        "(scene JSON; on input a GeoJSON FeatureCollection is also recognised), .geojson "
        "(FeatureCollection with properties.role = bounds/obstacle/target/goal/failure/start) "
        "or .wkt ('role: WKT' lines).  The input is fully validated; obstacles with holes are "
        "split into simple polygons.  The input may also be a bundled scene name "
        "(sensorplan convert lab lab.geojson).  See geometry.formats for the formats.",
    )
    c.add_argument(
        "input",
        help="input: a file (.json, .geojson or .wkt) or a bundled scene name "
        "(lab, edr, corridor, warehouse)",
    )
    c.add_argument("output", help="output file (.json, .geojson or .wkt)")
    c.add_argument("--name", default=None, help="scene name (default: from the input)")

    r = sub.add_parser(
        "record",
        help="record one episode to a rollout file for `sensorplan view --rollout`",
        description="Play one episode with a policy and save it (poses, beams, target, the "
        "exact region) as rollout JSON; `sensorplan view SCENE --rollout FILE` replays it "
        "(see sensorplan_gym.viewer.replay).",
    )
    r.add_argument("--env", default="sensorplan/Recognize-v0", help=ENV_CHOICES_HELP)
    r.add_argument(
        "--policy", default="oracle", help="'oracle' (default), 'random' or a model zip path"
    )
    r.add_argument(
        "--scene",
        default="lab",
        help="bundled scene name or scene file: scene JSON, GeoJSON or WKT (default: lab)",
    )
    r.add_argument("--seed", type=int, default=0)
    r.add_argument("--max-steps", type=int, default=None)
    r.add_argument("--env-kwargs", type=_json_dict, default=None, help="JSON gym.make kwargs")
    r.add_argument("--out", default="rollout.json", help="rollout file (default rollout.json)")

    d = sub.add_parser(
        "dataset",
        help="record oracle demonstrations as a Minari dataset (agents/learning/dataset.py)",
    )
    dsub = d.add_subparsers(dest="dataset_command", metavar="{record}")
    dsub.required = True
    dr = dsub.add_parser(
        "record",
        help="play the oracle and write a Minari dataset (minari.load_dataset loads it)",
    )
    dr.add_argument("--env", required=True, help=ENV_CHOICES_HELP)
    dr.add_argument("--episodes", type=int, required=True)
    dr.add_argument(
        "--dataset-id", required=True, help="Minari id 'namespace/name-v0', e.g. sensorplan/lab-v0"
    )
    dr.add_argument("--seed", type=int, default=0, help="episode k is reset with seed + k")
    dr.add_argument("--env-kwargs", type=_json_dict, default=None, help="JSON gym.make kwargs")
    dr.add_argument(
        "--data-path", default=None, help="dataset folder (default: Minari's, ~/.minari/datasets)"
    )
    dr.add_argument("--overwrite", action="store_true", help="replace a dataset of that id")

    im = sub.add_parser(
        "imitate",
        help="learn from the oracle: bc, dagger, dagger+ppo (or ppo from scratch)",
        description="Behaviour cloning / DAgger on the batched env with the oracle (or, "
        "config key expert: hint-rule, the fixed rule on view_hint) as the expert, optionally "
        "followed by PPO fine-tuning; hyperparameters from agents/configs/imitation.yaml "
        "(see agents/learning/imitation.py; agents/configs/imitation_hint.yaml trains the "
        "shipped dagger_navigate_hint).",
    )
    im.add_argument(
        "--env",
        required=True,
        help=ENV_CHOICES_HELP + "; watch_v0: the watchers (agents/configs/watch_imitation.yaml)",
    )
    im.add_argument("--method", default="dagger", choices=("bc", "dagger", "dagger+ppo", "ppo"))
    im.add_argument("--seed", type=int, default=0)
    im.add_argument("--config", default=None, help="YAML (default agents/configs/imitation.yaml)")
    im.add_argument(
        "--out", default=None, help="output folder (default runs/<method>_<env>_s<seed>)"
    )
    im.add_argument(
        "--wall-s", type=float, default=None, help="wall-clock budget in seconds for the run"
    )
    im.add_argument(
        "--overrides",
        type=_json_dict,
        default=None,
        help="JSON merged into the config section, e.g. '{\"n_envs\": 16}'",
    )
    return parser


def _missing_extra_message(command: str, err: ImportError) -> str | None:
    """The 'install this extra' message of ``sensorplan <command>`` for an ImportError of an
    optional dependency, or ``None`` when the module belongs to no extra (re-raise it)."""
    return missing_extra_message(f"sensorplan {command}", err)


def _hp_overrides(items: list[str] | None) -> dict:
    """``["n_steps=64", "policy_kwargs={net_arch: [32]}"]`` -> a dict (values read as YAML)."""
    import yaml

    out = {}
    for item in items or []:
        key, sep, value = item.partition("=")
        if not sep or not key:
            raise ValueError(f"--hp wants KEY=VALUE, got {item!r}")
        try:
            v = yaml.safe_load(value)
        except yaml.YAMLError as e:
            raise ValueError(f"--hp {key}: {value!r} is not a YAML value ({e})") from e
        if isinstance(v, str):  # YAML 1.1 reads 1e-4 as a string
            try:
                v = float(v)
            except ValueError:
                pass
        out[key] = v
    return out


def _record(args: argparse.Namespace) -> int:
    """``sensorplan record``: the viewer's recorder (below the agents) gets the policy from
    here (:func:`agents.learning.policies.load_policy`)."""
    from sensorplan_gym.viewer.replay import record_rollout, save_rollout

    from .learning.policies import check_policies, load_policy

    check_writable_file(args.out)
    spec = args.policy
    check_policies([spec])
    if spec == "random":
        policy: object = "random"
    else:
        policy = lambda env: load_policy(spec, env, seed=args.seed)  # noqa: E731
    ro = record_rollout(
        args.env,
        policy=policy,
        policy_name=spec,
        seed=args.seed,
        max_steps=args.max_steps,
        **{**(args.env_kwargs or {}), "scene": args.scene},
    )
    p = save_rollout(ro, args.out)
    print(f"wrote {p}: {len(ro['steps']) - 1} steps, return {ro['return']:.3f}")
    return 0


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv and argv[0] == "demo":
        try:
            from . import demo  # lazily: the demo pulls in plotting and the oracle

            rc = demo.main(argv[1:])
        except ImportError as err:
            msg = _missing_extra_message("demo", err)
            if msg is None:
                raise
            print(msg, file=sys.stderr)
            return 2
        return int(rc or 0)
    if argv and argv[0] == "view":
        from sensorplan_gym.viewer.cli import main as view_main  # lazily: Bokeh is an extra

        return int(view_main(argv[1:]) or 0)
    args = build_parser().parse_args(argv)
    try:
        if args.command == "convert":
            from geometry.formats import save_scene_file
            from sensorplan_gym.core.scenes import load_scene

            scene = load_scene(args.input, name=args.name)
            try:
                save_scene_file(scene, args.output)
            except OSError as e:
                raise ValueError(f"cannot write {args.output}: {e.strerror or e}") from None
            n_edges = len(scene.bounds) + sum(len(o) for o in scene.obstacles)
            print(
                f"{args.input} -> {args.output}: scene {scene.name!r}, "
                f"{len(scene.obstacles)} obstacles, {n_edges} edges"
            )
            return 0
        if args.command == "record":
            return _record(args)
        if args.command == "train" and args.backend == "rllib":
            from .learning.rllib_train import train_rllib

            res = train_rllib(
                args.config,
                seed=args.seed,
                iterations=args.iterations,
                address=args.address,
                out=args.out,
                env_kwargs=args.env_kwargs,
            )
            print(f"checkpoint: {res['checkpoint']}  ({res['wall_s']:.0f} s)")
            return 0
        if args.command == "train":
            if args.env is None or args.algo is None:
                raise ValueError("--env and --algo are required with --backend sb3")
            from .learning.train import default_out, train

            hp = _hp_overrides(args.hp)
            seeds = args.seeds or [args.seed]
            for s in seeds:
                out = args.out
                if args.seeds:
                    out = f"{args.out}_s{s}" if args.out else default_out(args.algo, args.env, s)
                train(
                    args.env,
                    args.algo,
                    timesteps=args.timesteps,
                    seed=s,
                    n_envs=args.n_envs,
                    env_kwargs=args.env_kwargs,
                    config=args.config,
                    out=out,
                    eval_freq=args.eval_freq,
                    eval_episodes=args.eval_episodes,
                    vec_env=args.vec_env,
                    threads=args.threads,
                    progress_bar=False if args.no_progress else None,
                    tensorboard=False if args.no_tensorboard else None,
                    hp_overrides=hp,
                    checkpoint_freq=args.checkpoint_freq,
                    resume=args.resume,
                )
            return 0
        if args.command == "dataset":
            from .learning.dataset import record_dataset

            ds = record_dataset(
                args.env,
                args.dataset_id,
                args.episodes,
                env_kwargs=args.env_kwargs,
                seed=args.seed,
                data_path=args.data_path,
                overwrite=args.overwrite,
            )
            print(f"{args.dataset_id}: {ds.total_episodes} episodes, {ds.total_steps} steps")
            return 0
        if args.command == "imitate" and args.env == "watch_v0":
            from .learning.watch_imitation import train_watch_imitation

            if args.method != "dagger":
                raise ValueError(f"--env watch_v0 learns by --method dagger, got {args.method!r}")
            rec = train_watch_imitation(
                args.config,
                seed=args.seed,
                out=args.out,
                wall_s=args.wall_s,
                overrides=args.overrides,
            )
            print(f"policy: {rec['out']}/final_model.pt  ({rec['wall_time_s']} s)")
            return 0
        if args.command == "imitate":
            from .learning.imitation import train_imitation

            rec = train_imitation(
                args.env,
                args.method,
                config=args.config,
                seed=args.seed,
                out=args.out,
                wall_s=args.wall_s,
                overrides=args.overrides,
            )
            print(f"model: {rec['out']}/final_model.zip  ({rec['wall_time_s']} s)")
            return 0
        if args.command == "benchmark":
            from .evaluation.benchmark import DEFAULT_DIFFICULTY, benchmark

            benchmark(
                args.env,
                args.policies,
                episodes=args.episodes,
                seed=args.seed,
                difficulty=(
                    args.difficulty
                    if args.difficulty is not None
                    else (None if args.level else DEFAULT_DIFFICULTY)
                ),
                split_names=args.splits,
                level=args.level,
                env_kwargs=args.env_kwargs,
                out=args.out,
                deterministic=not args.stochastic,
            )
            return 0
        if args.command == "evaluate":
            from .evaluation.evaluate import evaluate

            evaluate(
                args.env,
                args.policies,
                episodes=args.episodes,
                seed=args.seed,
                env_kwargs=args.env_kwargs,
                out=args.out,
                plot=not args.no_plot,
                backend=args.backend,
                address=args.address,
                deterministic=not args.stochastic,
            )
            return 0
    except ImportError as err:
        msg = _missing_extra_message(args.command, err)
        if msg is None:
            raise
        print(msg, file=sys.stderr)
        return 2
    except (ValueError, KeyError, FileNotFoundError, NotImplementedError) as err:
        msg = err.args[0] if isinstance(err, KeyError) and err.args else err
        print(f"sensorplan {args.command}: error: {msg}", file=sys.stderr)
        return 2
    except OSError as err:  # e.g. a folder that became unwritable while running
        where = f": {err.filename}" if err.filename else ""
        print(f"sensorplan {args.command}: error: {err.strerror or err}{where}", file=sys.stderr)
        return 2
    return 1  # pragma: no cover - argparse rejects unknown commands


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
