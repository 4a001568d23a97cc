"""The tasks: each environment id is one small declaration, a :class:`Task`, naming its command
interfaces (:mod:`rotordrop_env.commands`), its reward (:mod:`rotordrop_env.reward`), the
constraints that end its episodes (:mod:`rotordrop_env.constraints`), the scene keys it needs
and its scenario draw (:mod:`rotordrop_env.scenario`). The observation follows from the
interfaces (:mod:`rotordrop_env.layout`). Declaring and registering tasks imports no physics
(the environment checks a task's pieces when it is made).

    from rotordrop_env.tasks import TASKS, Task
    catch = Task("Catch", version=0, commands=("amb",), command="continuous",
                 power_return_time=0.0, reward="kpi")
    with TASKS.temporary(catch):                 # or TASKS.register(catch) for the session
        env = gymnasium.make("RotorDrop-Catch-v0")

:data:`TASKS` holds the shipped tasks; ``rotordrop_env.ENV_IDS`` is derived from it.
"""
from __future__ import annotations

import re
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any, Mapping

from .events import EventRanges

ENV_MODULE, VECTOR_MODULE = "rotordrop_env.env", "rotordrop_env.vector"
DAMPER, AMB = "damper", "amb"
#: the command interfaces (:mod:`rotordrop_env.commands`), in the order of their action
#: entries, and the scene keys each needs (set by the environment)
INTERFACES: dict[str, Mapping[str, object]] = {
    DAMPER: {"effects.semi_active_damper": True},
    AMB: {"effects.amb": "actuator"},
}
#: the episode constraints' names (:data:`rotordrop_env.constraints.CONSTRAINTS`)
CONSTRAINT_NAMES = ("stator_contact", "bearing_overload", "contact_validity")
DEFAULT_POWER_RETURN = 0.05


def check_interfaces(names) -> tuple[str, ...]:
    """A task's ``commands``: known interfaces, each once, in the order of :data:`INTERFACES`."""
    names = (names,) if isinstance(names, str) else tuple(names)
    for name in names:
        if name not in INTERFACES:
            raise ValueError(f"command interface {name!r} is not one of "
                             + ", ".join(repr(n) for n in INTERFACES))
    if list(names) != [n for n in INTERFACES if n in names]:
        raise ValueError(f"command interfaces {names!r}: give each once, in the order "
                         + ", ".join(INTERFACES) + " (the order of the action entries)")
    return names


@dataclass(frozen=True)
class Task:
    """One environment task, registered as ``RotorDrop-<name>-v<version>``.

    ``commands``: its command interfaces (``"damper"``, ``"amb"``; none: the action is
    ignored); ``command``, ``power_return_time``: the AMB interface's defaults; ``reward``,
    ``constraints``: the defaults of the env kwargs of the same names; ``scene``: scene keys it
    forces beyond its interfaces' (e.g. ``{"effects.stator_contact": True}``);
    ``randomization``: its scenario draw with ``randomize=True``, ranges over
    :data:`rotordrop_env.scenario.DEFAULT_RANGES` (None leaves a default key out);
    ``env_class``: the name of its own class in :mod:`rotordrop_env.env` (the shipped tasks),
    else the environment is ``RotorDropEnv(task=...)``. ``amb_on``: the AMBs stay powered and
    the built-in PID levitates from the episode start (no fault; the AMB commands act from the
    first step); ``events``: the event drawn per episode
    (:class:`rotordrop_env.events.EventRanges`, None: no event); ``relevitation_hold``: the
    default of the env kwarg; ``latched``: False makes the success region's verdict the
    present one (contact-free for the hold *now*, lost again on contact) instead of latched at
    its first success; ``success_radius``: the success region's radius (fraction of the
    clearance; within it and without contact at both retainer planes)."""
    name: str
    commands: tuple[str, ...] = ()
    version: int = 1
    command: str = "discrete"
    power_return_time: float = DEFAULT_POWER_RETURN
    reward: str = "default"
    constraints: tuple[str, ...] = CONSTRAINT_NAMES
    scene: Mapping[str, Any] = field(default_factory=dict)
    randomization: Mapping[str, Any] = field(default_factory=dict)
    summary: str = ""
    env_class: str | None = None
    amb_on: bool = False
    events: Any = None
    relevitation_hold: float = 0.02
    latched: bool = True
    success_radius: float = 0.5

    def __post_init__(self):
        if not re.fullmatch(r"[A-Z][A-Za-z0-9]*", str(self.name)):
            raise ValueError(f"task name {self.name!r} must be CamelCase letters and digits "
                             "(it names the id RotorDrop-<name>-v<version>)")
        if not isinstance(self.version, int) or self.version < 0:
            raise ValueError(f"task {self.name}: version = {self.version!r} must be an int >= 0")
        object.__setattr__(self, "commands", check_interfaces(self.commands))
        object.__setattr__(self, "constraints", tuple(self.constraints))
        # command, reward and constraints are checked as an environment is made (each by the
        # module that owns it), so that declaring tasks imports no physics

    @property
    def env_id(self) -> str:
        return f"RotorDrop-{self.name}-v{self.version}"

    @property
    def damper(self) -> bool:
        """The agent commands the support dampers."""
        return DAMPER in self.commands

    @property
    def amb(self) -> bool:
        """The agent commands the AMBs once power returns (a re-levitation task)."""
        return AMB in self.commands

    @property
    def entry_point(self) -> str:
        return f"{ENV_MODULE}:{self.env_class or 'RotorDropEnv'}"

    @property
    def vector_entry_point(self) -> str:
        cls = (self.env_class or "RotorDropEnv").replace("Env", "VectorEnv")
        return f"{VECTOR_MODULE}:{cls}"

    @property
    def gym_kwargs(self) -> dict:
        """The kwargs ``gym.make`` adds: none for a task with its own class, else the task."""
        return {} if self.env_class else {"task": self}


PASSIVE = Task("Passive", env_class="PassiveEnv",
               summary="the paper's passive drop; the action does nothing")
DAMPING = Task("Damping", commands=(DAMPER,), env_class="DampingEnv",
               summary="semi-active support damping of each housing")
RELEVITATE = Task("Relevitate", commands=(AMB,), env_class="RelevitateEnv",
                  summary="AMB reactivation after the power returns")
FULL = Task("Full", commands=(DAMPER, AMB), env_class="FullEnv",
            summary="semi-active damping and AMB reactivation together")


RECOVER = Task("Recover", commands=(AMB,), command="supervisor", power_return_time=0.0,
               amb_on=True, events=EventRanges(), relevitation_hold=0.05, latched=False,
               scene={"amb.off_time": 0.01}, success_radius=1.0,
               randomization={"power_return_time": None},
               summary="recovery with the AMBs on after a shock, a sudden unbalance or a "
                       "transient load")


class TaskRegistry(dict):
    """Tasks by env id (a dict: looking one up runs no Python code of this module), each
    registered with Gymnasium as it is added (:meth:`register`); :meth:`temporary` registers
    one for a ``with`` block only. ``entry_points``: each id's entry point (a dict kept in step,
    ``rotordrop_env.ENV_IDS``)."""

    def __init__(self, *tasks: Task):
        super().__init__()
        self.entry_points: dict[str, str] = {}
        for task in tasks:
            self.register(task)

    def __setitem__(self, env_id, task):
        raise TypeError("add a task with register(task) (it registers its Gymnasium id too)")

    def register(self, task: Task) -> Task:
        """Add ``task`` and register its id with Gymnasium (``gym.make``, ``gym.make_vec``);
        ValueError if its id is taken."""
        from gymnasium.envs.registration import register, registry
        if not isinstance(task, Task):
            raise ValueError(f"{task!r} is not a rotordrop_env.tasks.Task")
        if task.env_id in self:
            raise ValueError(f"{task.env_id} is already a task")
        if task.env_id in registry and registry[task.env_id].entry_point != task.entry_point:
            raise ValueError(f"{task.env_id} is already a Gymnasium id of another environment")
        if task.env_id not in registry:
            register(id=task.env_id, entry_point=task.entry_point,
                     vector_entry_point=task.vector_entry_point, kwargs=task.gym_kwargs)
        dict.__setitem__(self, task.env_id, task)
        self.entry_points[task.env_id] = task.entry_point
        return task

    def unregister(self, env_id: str) -> Task:
        """Remove a task and its Gymnasium id."""
        from gymnasium.envs.registration import registry
        task = self.pop(env_id)
        del self.entry_points[env_id]
        registry.pop(env_id, None)
        return task

    @contextmanager
    def temporary(self, task: Task):
        """``task`` registered inside the ``with`` block, gone after it (also on an error)."""
        self.register(task)
        try:
            yield task
        finally:
            self.unregister(task.env_id)


#: the shipped tasks (and any registered in this process)
TASKS = TaskRegistry(PASSIVE, DAMPING, RELEVITATE, FULL, RECOVER)


def resolve_task(env_class: type, task: Task | None) -> Task:
    """The task an environment of ``env_class`` runs: the ``task`` kwarg, else its class's (a
    shipped task's class; ``RotorDropEnv`` alone runs the passive drop); ValueError for a
    non-task, or another task than the class's."""
    own = getattr(env_class, "task", None)
    if task is not None and not isinstance(task, Task):
        raise ValueError(f"task = {task!r} must be a rotordrop_env.tasks.Task")
    if task is not None and own is not None and task != own:
        raise ValueError(f"{env_class.__name__} runs the {own.name} task, not task={task!r}")
    return task or own or PASSIVE
