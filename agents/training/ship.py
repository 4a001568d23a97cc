"""Ship a training run as a policy of ``agents/policies/`` (``<name>.zip``, ``.pkl``, ``.json``):
how the shipped policies are made. A maintainer's tool::

    python -m agents.training.ship runs/ppo-full ppo-full [--best] [--notes TEXT] [--command CMD]

The zip is self-contained (:func:`agents.learning.policies.export_policy`: it runs under plain
SB3 as it is), the ``.pkl`` is the run's VecNormalize statistics and the JSON records the
command and seed that reproduce the run, its training time and a learning-curve summary.
"""
from __future__ import annotations

import argparse
import json
import re
import shutil
import sys
from pathlib import Path

from ..benchmarking.score import write_json
from ..learning.hyperparams import ALGOS as ALGO_NAMES
from ..learning.policies import export_policy, shipped_dir


def ship_policy(run_dir: str | Path, name: str, which: str = "final", dest: Path | None = None,
                notes: str = "", command: str | None = None) -> Path:
    """Export a training run's model (self-contained, :func:`export_policy`) and copy its
    statistics into ``agents/policies/<name>.*``.

    ``which`` = ``final`` (``model.zip``) or ``best`` (``best/best_model.zip``). The JSON records
    the command and seed that reproduce the run (``command`` overrides the recorded one, e.g.
    when the run's ``--config`` has become the shipped default), its training time and a
    learning-curve summary.
    """
    run = Path(run_dir)
    dest = Path(dest) if dest is not None else shipped_dir()
    algo = name.split("-")[0]
    if algo not in ALGO_NAMES:
        raise ValueError(f"a shipped policy's name starts with its algorithm ({', '.join(ALGO_NAMES)}), "
                         f"got {name!r}")
    model, vn = ((run / "model.zip", run / "vecnormalize.pkl") if which == "final"
                 else (run / "best" / "best_model.zip", run / "best" / "vecnormalize.pkl"))
    info = json.loads((run / "training.json").read_text())
    export_policy(model, dest / f"{name}.zip")            # runs under plain SB3 as it is
    shutil.copyfile(vn, dest / f"{name}.pkl")
    curve = info.get("learning_curve", [])
    summary = [{k: (round(v, 4) if isinstance(v, float) else v) for k, v in h.items()
                if k in ("timesteps", "mean_reward", "mean_failure", "mean_backward_whirl",
                         "mean_peak_contact_force_N", "mean_relevitated")} for h in curve]
    command = command or re.sub(r"--out \S+", f"--out runs/{name}", info["command"])
    meta = dict(name=name, algo=info["algo"], env_id=info["env_id"],
                env_kwargs=info["hyperparams"].get("env_kwargs", {}), model=which,
                command=command, seed=info["seed"], timesteps=info["timesteps"],
                training_wall_time_s=round(info["wall_time_s"], 1),
                steps_per_s=round(info["steps_per_s"], 1) if info.get("steps_per_s") else None,
                threads=info.get("threads"), versions=info.get("versions"),
                hyperparams=info["hyperparams"], learning_curve=summary, notes=notes)
    write_json(dest / f"{name}.json", meta, indent=1)
    return dest / f"{name}.zip"


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m agents.training.ship",
                                description="ship a training run as a policy of agents/policies/")
    p.add_argument("run_dir", help="the --out directory of a `rotordrop train` run")
    p.add_argument("name", help="the policy's name, starting with its algorithm (e.g. ppo-full)")
    p.add_argument("--best", action="store_true", help="ship best/best_model.zip (default: model.zip)")
    p.add_argument("--notes", default="", help="notes recorded in the JSON")
    p.add_argument("--command", default=None, help="the command recorded in the JSON (default: the run's)")
    p.add_argument("--dest", default=None, help="directory (default: the package's agents/policies/)")
    args = p.parse_args(argv)
    try:
        out = ship_policy(args.run_dir, args.name, which="best" if args.best else "final",
                          dest=args.dest, notes=args.notes, command=args.command)
    except (ValueError, FileNotFoundError, KeyError) as exc:
        print(f"{p.prog}: error: {exc}", file=sys.stderr)
        return 2
    print(f"wrote {out}, {out.with_suffix('.pkl')}, {out.with_suffix('.json')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
