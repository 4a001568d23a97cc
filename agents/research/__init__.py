"""``rotordrop research whirl-bound | tune-whirl-brake | tune-designed | seat-oracle | recover-oracle``: research probes of the re-levitation
task (docs/agents.md), kept apart from the speed scripts in ``benchmarks/``.

``whirl-bound`` (:mod:`agents.research.whirl_bound`) searches the AMB current sequence with the
fewest backward-whirl revolutions in a known scenario, an empirical lower bound for feedback
control; ``tune-whirl-brake`` (:mod:`agents.research.tune_whirl_brake`) tunes the gains of the
``whirl-brake`` baseline on scenarios the benchmark does not use; ``seat-oracle``
(:mod:`agents.research.seat_oracle`) scores each test drop by the best of a pool of
``whirl-brake`` gain sets in the law's seat (a searched plan that knows the drop);
``recover-oracle`` (:mod:`agents.research.recover_oracle`) scores each Recover test event by the
best of a pool of designed recovery plans in their seats. Registration is light: the
environments are imported by the handlers.
"""
from __future__ import annotations

from physics.runs.backend import add_backend_args
from physics.cli import at_least
from physics.runs import UsageError


def register(subparsers) -> None:
    p = subparsers.add_parser("research", help="research probes of the re-levitation task: the "
                                               "oracle whirl bound, whirl-brake gain tuning")
    sub = p.add_subparsers(dest="research", required=True)

    q = sub.add_parser("whirl-bound", help="how few backward-whirl revolutions can any AMB current "
                                           "sequence reach once the power is back? (whirl_bound.json)")
    q.add_argument("--env", default="RotorDrop-Relevitate-v1",
                   help="RotorDrop-Relevitate-v1 or RotorDrop-Full-v1")
    q.add_argument("--baseline", default="whirl-brake",
                   help="a controller that commands the AMB currents: baseline name, "
                        "module:Class or file.py:Class")
    q.add_argument("--friction", type=float, action="append", default=None,
                   help="repeatable; default 0.48 and 0.53 (the benchmark's mu* + 0.10, + 0.15)")
    q.add_argument("--phase", type=float, action="append", default=None,
                   help="unbalance phase [deg], repeatable; default 0 and 180")
    q.add_argument("--delay-ms", type=float, default=50.0, help="power-return delay [ms]")
    q.add_argument("--segments", type=at_least(1), default=16)
    q.add_argument("--steps", type=at_least(1), default=2, help="control steps per segment")
    q.add_argument("--iterations", type=at_least(1), default=25)
    q.add_argument("--population", type=at_least(1), default=32)
    q.add_argument("--std", type=float, default=0.5, help="initial search spread (current limit = 1)")
    q.add_argument("--seed", type=at_least(0), default=0)
    q.add_argument("--out", default="out/whirl_bound")
    q.set_defaults(func=cmd_whirl_bound)

    from agents.benchmarking.tune_designed import DESIGNED, LEARNED_SELECTION_EPISODES
    q = sub.add_parser("tune-designed", help="tune every designed law with constants on a suite's "
                                             "validation drops, in its seat, and store the "
                                             "constants with what they were tuned under")
    q.add_argument("--suite", default="robust", help="the suite whose validation drops tune "
                                                     "(default robust; recover or "
                                                     "recover-robust: the recovery laws on its "
                                                     "validation events)")
    q.add_argument("--law", action="append", default=None,
                   help=f"a designed law to tune (repeatable; default all: {', '.join(DESIGNED)})")
    q.add_argument("--episodes", type=at_least(LEARNED_SELECTION_EPISODES),
                   default=LEARNED_SELECTION_EPISODES,
                   help=f"validation episodes per law, at least (and by default) "
                        f"{LEARNED_SELECTION_EPISODES}: one learned configuration's model "
                        "selection (1e6 steps scored every 10 000 on the 20 validation drops)")
    q.add_argument("--seed", type=at_least(0), default=0, help="search seed")
    q.add_argument("--out", default=None, help="also write the records here")
    q.add_argument("--quiet", action="store_true", help="no progress bar")
    q.set_defaults(func=cmd_tune_designed)

    q = sub.add_parser("seat-oracle", help="per test drop, the best of a pool of whirl-brake "
                                           "gain sets in its seat (inside the AMB controller): "
                                           "a searched plan that knows the drop, against the "
                                           "tuned law (seat_oracle.json)")
    q.add_argument("--suite", default="robust", help="a drawn suite (default robust)")
    q.add_argument("--scenarios", type=at_least(1), default=50,
                   help="its first test drops (default 50)")
    q.add_argument("--draws", type=at_least(0), default=8,
                   help="gain sets drawn around the tuned gains, besides the tuned, the class "
                        "defaults and whirl-brake-robust's (default 8)")
    q.add_argument("--spread", type=float, default=0.1,
                   help="std of a draw as a fraction of each gain's tuning range (default 0.1)")
    q.add_argument("--seed", type=at_least(0), default=0, help="seed of the draws")
    q.add_argument("--out", default="out/seat-oracle")
    q.add_argument("--quiet", action="store_true", help="no progress bar")
    add_backend_args(q, resume=False)
    q.set_defaults(func=cmd_seat_oracle)

    q = sub.add_parser("recover-oracle", help="per Recover test event, the best of a pool of "
                                              "designed recovery plans in their seats: a "
                                              "searched plan that knows the event, against the "
                                              "PID (oracle_recover.json)")
    q.add_argument("--suite", default="recover", help="recover or recover-robust (default recover)")
    q.add_argument("--events", type=at_least(1), default=100,
                   help="its first test events (default 100)")
    q.add_argument("--seat", action="append", default=None, choices=("supervisor", "controller"),
                   help="the seats whose plans run (repeatable; default supervisor)")
    q.add_argument("--out", default="out/recover-oracle")
    q.add_argument("--quiet", action="store_true", help="no progress bar")
    q.set_defaults(func=cmd_recover_oracle)

    q = sub.add_parser("tune-whirl-brake", help="tune the whirl-brake baseline's gains by "
                                                "cross-entropy search on a tuning set (tune.json)")
    q.add_argument("--env", default="RotorDrop-Relevitate-v1",
                   help="RotorDrop-Relevitate-v1 or RotorDrop-Full-v1")
    q.add_argument("--iterations", type=at_least(1), default=12)
    q.add_argument("--population", type=at_least(1), default=24)
    q.add_argument("--elite", type=at_least(1), default=6)
    q.add_argument("--seed", type=at_least(0), default=0)
    q.add_argument("--out", default="out/tune_whirl_brake")
    add_backend_args(q, resume=False)
    q.set_defaults(func=cmd_tune_whirl_brake)


def cmd_tune_designed(args) -> int:
    from agents.benchmarking.suites import SUITES
    from agents.benchmarking.tune_designed import tune_designed

    def run(a):
        tune_designed(SUITES.get(a.suite, "tune"), a.law, a.episodes, a.seed, not a.quiet, a.out)
    return _usage_errors(run, args)


def cmd_whirl_bound(args) -> int:
    from .whirl_bound import run
    return _usage_errors(run, args)


def cmd_seat_oracle(args) -> int:
    from .seat_oracle import run
    return _usage_errors(run, args)


def cmd_recover_oracle(args) -> int:
    from .recover_oracle import run
    return _usage_errors(run, args)


def cmd_tune_whirl_brake(args) -> int:
    from .tune_whirl_brake import run
    return _usage_errors(run, args)


def _usage_errors(run, args) -> int:
    """``run(args)``; a bad option value (ValueError, FileNotFoundError) is a one-line UsageError."""
    try:
        run(args)
    except (ValueError, FileNotFoundError) as exc:
        raise UsageError(exc.args[0] if len(exc.args) == 1 else exc) from None
    return 0
