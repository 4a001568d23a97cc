"""Benchmark suites as registered objects: ``--suite`` of ``rotordrop benchmark``, ``tune``,
``tune-designed`` and ``oracle``.

A :class:`Suite` draws its scenarios, owns its seeds (the test drops from ``seed``, the
validation drops from ``validation_seed``; never shared) and its power-return rounding
(:meth:`Suite.round_power`), and says which commands can run it (``purposes``). Commands look a
suite up in a :class:`SuiteRegistry` by name (:data:`SUITES`, or a registry of their own, e.g. a
test's temporary one) and then only ask the object: no command compares suite names.

* :class:`NominalSuite` -- the fixed scenarios around the passive threshold
  (:mod:`agents.benchmarking.benchmark`), validated on the nominal validation set.
* :class:`DrawnSuite` -- drops of one task drawn one per seed by a ``draw(seed, name)``
  function: ``robust`` and ``robust-legacy`` (:mod:`agents.benchmarking.robust`, the same
  distribution on two test-seed ranges) and ``full`` (the oracle's drops, agents.research.oracle).

docs/howto/benchmark-suite.md registers a suite of one's own.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Callable

from .benchmark import round_up

#: the Recover suites' machine: the paper machine with a stiffer retainer support and a heavy
#: unbalance (assumed, from the persistence study: at 4000-5000 rpm the built-in PID holds it
#: contact-free without an event and in a persistent forward rub after some shocks), its event
#: ranges, and the suites' env kwargs: the nominal suite draws the speed and the event only;
#: the robust one the machine around it too, with 2 µm sensor noise and 50 µs sensor delay
RECOVER_MACHINE = {"support.stiffness": 5e8, "unbalance.mass": 0.2}
RECOVER_EVENTS = {"shock_peak_g": (2.0, 10.0), "unbalance_me": (0.01, 0.03),
                  "load_peak": (1000.0, 6000.0), "load_duration": (0.005, 0.03)}
RECOVER_NOMINAL: dict = {
    "overrides": RECOVER_MACHINE, "randomize": True, "episode_time": 0.5, "events": RECOVER_EVENTS,
    "randomization": {"rotor.speed_rpm": (4000.0, 5000.0), "contact.friction": None,
                      "support.damping": None}}
RECOVER_ROBUST: dict = {
    "randomize": True, "episode_time": 0.5, "events": RECOVER_EVENTS,
    "sensor_noise": 2e-6, "sensor_delay": 5e-5,
    "randomization": {"rotor.speed_rpm": (3500.0, 5500.0), "unbalance.mass": (0.15, 0.25),
                      "support.stiffness": ("log_uniform", 2e8, 1e9)}}
#: what a command may run a suite for
PURPOSES = ("benchmark", "tune", "oracle")




@dataclass(frozen=True)
class Suite:
    """A set of scenarios (module doc). ``seed``: the first test drop's seed (None: a fixed
    suite); ``size`` / ``quick_size``: test drops (``--quick``); ``validation_seed`` /
    ``validation_size``: the validation drops (tuning and model selection); ``power_grid`` [s]:
    the power return's rounding; ``env_id``: the one task it scores (None: every task)."""
    name: str
    about: str
    purposes: tuple[str, ...] = ("benchmark",)
    seed: int | None = None
    size: int = 0
    quick_size: int = 0
    validation_seed: int | None = None
    validation_size: int = 0
    power_grid: float = 0.005
    env_id: str | None = None
    tuned_on: str | None = None     # the suite whose validation drops tuned its designed rows
    train_kwargs: Callable | None = field(default=None, compare=False)

    def training_env_kwargs(self, control_dt: float) -> dict:
        """The env kwargs that train on this suite's distribution at ``control_dt`` (a fixed
        suite: the step alone)."""
        return self.train_kwargs(control_dt) if self.train_kwargs else {"control_dt": control_dt}

    def validation(self) -> list:
        """The validation drops (benchmark Scenarios)."""
        raise NotImplementedError

    def supports(self, purpose: str) -> bool:
        return purpose in self.purposes

    def round_power(self, t: float) -> float:
        """The power-return time ``t`` [s] on this suite's grid (:func:`round_up`)."""
        return round_up(t, self.power_grid)

    def test_seeds(self, n: int | None = None) -> range:
        return range(self.seed, self.seed + (self.size if n is None else n))

    def validation_seeds(self) -> range:
        return range(self.validation_seed, self.validation_seed + self.validation_size)

    def validator(self, env_id: str):
        """The validation set of ``env_id`` on this suite (:class:`~agents.benchmarking.benchmark.Validator`)."""
        raise NotImplementedError

    def run(self, out, **options) -> dict:
        """``rotordrop benchmark --suite NAME``: the report (benchmark.json's dict)."""
        raise NotImplementedError


@dataclass(frozen=True)
class NominalSuite(Suite):
    """The fixed nominal suite (:func:`agents.benchmarking.benchmark.scenario_suite`)."""

    def validator(self, env_id: str):
        from .benchmark import Validator
        return Validator(env_id)

    def validation(self) -> list:
        return self.validator(self.env_id or "RotorDrop-Full-v1").scenarios

    def run(self, out, **options) -> dict:
        from .benchmark import benchmark
        if options.pop("only", None):
            raise ValueError(f"--only applies to a drawn suite (one episode per drop), not to "
                             f"--suite {self.name}")
        return benchmark(out, **options)


@dataclass(frozen=True)
class DrawnSuite(Suite):
    """Drops drawn one per seed: ``draw(seed, name)`` returns the benchmark Scenario of that
    seed (its sensing included); the benchmark runs them with
    :func:`agents.benchmarking.robust.robust_benchmark`, one episode each. Without ``draw`` the
    drops are the task's own sampler's (the oracle's ``full`` suite, agents.research.oracle)."""
    draw: Callable | None = field(default=None, compare=False)
    describe: Callable | None = field(default=None, compare=False)   # report's distribution

    def scenarios(self, n: int | None = None, seed: int | None = None) -> list:
        """The first ``n`` (default ``size``) drops from ``seed`` (default the test seed)."""
        start = self.seed if seed is None else seed
        return [self.draw(start + i, f"#{i}") for i in range(self.size if n is None else n)]

    def validation(self) -> list:
        return self.scenarios(self.validation_size, self.validation_seed)

    def validator(self, env_id: str):
        from .benchmark import Validator
        if env_id != self.env_id:
            raise ValueError(f"the {self.name} suite's validation set is for {self.env_id}, "
                             f"not {env_id}")
        return Validator(env_id, self.validation(), (0.0,))

    def run(self, out, **options) -> dict:
        from .robust import robust_benchmark
        for flag in ("episodes", "power_return"):
            if options.pop(flag, None) is not None:
                raise ValueError(f"--{flag.replace('_', '-')}{'-ms' if flag == 'power_return' else ''} "
                                 f"does not apply to --suite {self.name} (its scenarios draw the "
                                 "power return; one episode each)")
        return robust_benchmark(out, suite=self, **options)


@dataclass(frozen=True)
class RecoverSuite(Suite):
    """Events of the ``Recover`` task, one per seed, drawn by the environment itself from its
    event distribution (and, with ``randomize`` in ``env_kwargs``, its machine ranges); run
    by :func:`agents.benchmarking.recover.recover_benchmark`. ``env_kwargs``: the suite's env
    kwargs beyond each law's seat (sensing, randomisation)."""
    env_kwargs: dict = field(default_factory=dict, compare=False)

    def validation(self) -> list:
        return list(self.validation_seeds())

    def validator(self, env_id: str):
        """All its validation events (:class:`agents.benchmarking.recover.RecoverValidator`)."""
        from .recover import ENV_ID, RecoverValidator
        if env_id != ENV_ID:
            raise ValueError(f"the {self.name} suite's validation events are for {ENV_ID}, "
                             f"not {env_id}")
        return RecoverValidator(self, self.validation_size)

    def run(self, out, **options) -> dict:
        from .recover import recover_benchmark
        return recover_benchmark(out, suite=self, **options)


class SuiteRegistry:
    """Suites by name. ``get(name, purpose)`` is the one place a name is looked up;
    :meth:`copy` gives a registry to add to without touching this one (tests, how-tos)."""

    def __init__(self, suites=()):
        self._suites: dict[str, Suite] = {}
        for s in suites:
            self.register(s)

    def register(self, suite: Suite) -> Suite:
        if suite.name in self._suites:
            raise ValueError(f"a suite named {suite.name!r} is registered already")
        if suite.seed is not None and suite.validation_seed is not None:
            test, val = suite.test_seeds(), suite.validation_seeds()
            if set(test) & set(val):
                raise ValueError(f"suite {suite.name!r}: its test seeds {test.start}-{test.stop - 1} "
                                 f"and validation seeds {val.start}-{val.stop - 1} overlap")
        self._suites[suite.name] = suite
        return suite

    def names(self, purpose: str | None = None) -> list[str]:
        return [n for n, s in self._suites.items() if purpose is None or s.supports(purpose)]

    def get(self, name: str, purpose: str = "benchmark") -> Suite:
        """The suite ``name``; ValueError naming the suites that serve ``purpose`` otherwise."""
        suite = self._suites.get(name)
        if suite is None or not suite.supports(purpose):
            raise ValueError(f"--suite = {name!r} must be one of {', '.join(self.names(purpose))}")
        return suite

    def copy(self) -> "SuiteRegistry":
        return SuiteRegistry(self._suites.values())

    def __iter__(self):
        return iter(self._suites.values())


def _registry() -> SuiteRegistry:
    from . import robust
    from .benchmark import TASKS
    drawn = dict(draw=robust.draw_scenario, describe=robust.distribution, env_id=TASKS["full"],
                 validation_seed=robust.VALIDATION_SEED, validation_size=robust.VALIDATION_SCENARIOS,
                 size=robust.SUITE_SCENARIOS, quick_size=robust.QUICK_SCENARIOS,
                 power_grid=robust.POWER_GRID, train_kwargs=robust.training_env_kwargs)
    robust_suite = DrawnSuite("robust", "the robust suite's test drops of the Full task "
                                        "(agents.benchmarking.robust)",
                              ("benchmark", "tune", "oracle"), seed=robust.SUITE_SEED, **drawn)
    return SuiteRegistry([
        NominalSuite("nominal", "the fixed scenario suite around the passive threshold",
                     ("benchmark", "tune")),
        robust_suite,
        replace(robust_suite, name="robust-legacy", about="the robust suite's earlier test drops",
                purposes=("benchmark",), seed=robust.LEGACY_SUITE_SEED, tuned_on="robust"),
        DrawnSuite("full", "drops of the Full task drawn by its own sampler from the oracle's "
                           "ranges (agents.research.oracle)", ("oracle",), seed=10_000,
                   env_id=TASKS["full"], power_grid=0.005),
        RecoverSuite("recover", "events of the Recover task on a machine with persistent "
                                "contact (agents.benchmarking.recover)", seed=60_000, size=200,
                     quick_size=40, validation_seed=61_000, validation_size=60,
                     purposes=("benchmark", "tune"),
                     env_id="RotorDrop-Recover-v1", env_kwargs=RECOVER_NOMINAL),
        RecoverSuite("recover-robust", "events of the Recover task on machines drawn around it, "
                                       "with sensor noise and delay",
                     seed=62_000, size=200, quick_size=40, validation_seed=63_000,
                     purposes=("benchmark", "tune"),
                     validation_size=60, env_id="RotorDrop-Recover-v1", env_kwargs=RECOVER_ROBUST),
    ])


#: the project's suites
SUITES = _registry()


def run_suite(suite: str, out, quick: bool = False, policies: list[str] | None = None,
              max_scenarios: int | None = None, episodes: int | None = None,
              progress: bool = True, plots: bool = True, power_return: float | None = None,
              backend=None, env_id: str | None = None, names: list[str] | None = None,
              score: str | None = None, registry: SuiteRegistry | None = None,
              only: list[str] | None = None) -> dict:
    """``rotordrop benchmark --suite SUITE``: the suite of that name in ``registry`` (default
    :data:`SUITES`) runs itself (:meth:`Suite.run`): the nominal one
    :func:`agents.benchmarking.benchmark.benchmark`, a drawn one
    :func:`agents.benchmarking.robust.robust_benchmark` (where ``episodes`` and
    ``power_return`` do not apply: its scenarios draw the power return, one episode each).
    ``score``: :data:`agents.benchmarking.score.SCORES` (default the first); ``only``: the
    baselines and shipped policies to run (drawn suites; ``passive`` and ``policies`` always)."""
    from .score import DEFAULT_SCORE, check_score
    score = check_score(score if score is not None else DEFAULT_SCORE)
    chosen = (registry or SUITES).get(suite, "benchmark")
    return chosen.run(out, quick=quick, policies=policies, max_scenarios=max_scenarios,
                      episodes=episodes, progress=progress, plots=plots, power_return=power_return,
                      backend=backend, env_id=env_id, names=names, score=score, only=only)
