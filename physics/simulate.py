"""Run a scene: levitated start, exact stop at the fault, dense output, clear errors."""
from __future__ import annotations

import time
from concurrent.futures import ThreadPoolExecutor
from concurrent.futures import TimeoutError as FutureTimeout

import numpy as np

from .equilibrium import levitated_state
from .integrate import (N_PEAK, NOT_FINITE, OK, SAMPLE_BLOCK, STEP_COLLAPSE, TOO_MANY_STEPS,
                        integrate_segment, sample_diagnostics)
from .model import EFFECTS, N_AUX, AMB_NONE, F_AMB, Model, build_model
from .results import Result, RunStats
from .scene import Scene, SceneError, param_meta

BAR_POLL_S = 0.1    # a progress bar reads the time the kernel has reached this often [s]
MAX_OUTPUT_BYTES = 2 * 1024 ** 3    # states + diagnostics kept in memory; the metrics, the time
                                    # series file and the figures need about as much again


class IntegrationError(RuntimeError):
    """The integrator could not advance (step-size collapse, step budget, non-finite state)."""


class Integrator:
    """Integrates one model; keeps the scratch arrays and the last step size between calls.

    ``advance(y, t0, t1, U, t_out, Y_out, pos)`` is what the drop driver and the environments
    call; it allocates nothing per call.
    """

    def __init__(self, model: Model):
        self.model = model
        sv = model.scene.solver
        self.fixed = sv.method == "fixed"
        self.rtol = sv.rtol
        self.atol = sv.rtol * model.scale
        self.h = sv.dt if self.fixed else min(1e-6, sv.max_step)
        self.h_max = sv.dt if self.fixed else sv.max_step
        self.h_min = sv.min_step
        self.max_steps = sv.max_steps
        self.work = np.empty((9, model.n_state))
        self.stats = RunStats()
        self._no_out = np.empty(0)
        self._no_Y = np.empty((0, model.n_state))

    def advance(self, y, t0, t1, U, t_out=None, Y_out=None, pos=0, peaks=None,
                clock=None) -> int:
        """Integrate t0 -> t1 (``peaks``: optional (2 N_PEAK,) step-resolved maxima to update;
        ``clock``: optional (1,) array that follows the time reached, for a progress bar)."""
        if t_out is None:
            t_out, Y_out = self._no_out, self._no_Y
        budget = self.max_steps - self.stats.steps
        args = (y, t0, t1, self.model.P, self.model.I, U, self.rtol, self.atol, self.h,
                self.h_max, self.h_min, self.fixed, budget, t_out, Y_out, pos, self.work)
        if clock is not None:
            args += (peaks, clock)
        elif peaks is not None:
            args += (peaks,)
        status, t, h, pos, n_rhs, n_steps, n_rej = integrate_segment(*args)
        st = self.stats
        st.rhs_evaluations += n_rhs
        st.steps += n_steps
        st.rejected_steps += n_rej
        if not self.fixed:
            self.h = h
        if status != OK:
            raise IntegrationError(explain_status(status, t, h, self.model))
        return pos


def explain_status(status: int, t: float, h: float, model: Model) -> str:
    """The error message of an integrator status; its advice stays inside the allowed ranges."""
    sv = model.scene.solver
    if status == STEP_COLLAPSE:
        return (f"step size collapsed to {h:.3g} s (< solver.min_step = {sv.min_step:g} s) at "
                f"t = {t:.6f} s: the scene is too stiff or singular there; " + " or ".join(
                    _moves(sv, ("loosen", "rtol", True), ("lower", "min_step", False))
                    + ["soften contact.stiffness / support.stiffness"]))
    if status == TOO_MANY_STEPS:
        head = (f"step budget solver.max_steps = {sv.max_steps} exhausted at t = {t:.6f} s "
                f"(last step {h:.3g} s)")
        if sv.method == "fixed":
            head += (f": the fixed step solver.dt = {sv.dt:g} s needs {sv.t_end / sv.dt:.3g} steps"
                     f" for solver.t_end = {sv.t_end:g} s")
            moves = _moves(sv, ("raise", "max_steps", True), ("raise", "dt", True))
        else:       # a step held at solver.max_step is not limited by the tolerance
            moves = _moves(sv, ("raise", "max_steps", True), ("raise", "max_step", True)
                           if h >= sv.max_step else ("loosen", "rtol", True))
        return f"{head}; " + " or ".join(moves or ["shorten solver.t_end"])
    if status == NOT_FINITE:
        return (f"the fixed-step solution became non-finite at t = {t:.6f} s with solver.dt = "
                f"{sv.dt:g} s: the step is beyond the stability limit; " + " or ".join(
                    _moves(sv, ("reduce", "dt", False)) + ["use solver.method = adaptive"]))
    return f"integration failed with status {status} at t = {t}"


def _moves(sv, *moves: tuple[str, str, bool]) -> list[str]:
    """'raise solver.X (now v, at most hi)' for each of ``moves`` (verb, solver key, upwards)
    that stays inside the key's allowed range."""
    out = []
    for verb, name, up in moves:
        value, meta = getattr(sv, name), param_meta(f"solver.{name}")
        bound = meta["hi"] if up else meta["lo"]
        if (value < bound) if up else (value > bound):
            out.append(f"{verb} solver.{name} (now {value:g}, {'at most' if up else 'at least'} "
                       f"{bound:g})")
    return out


def warm_up(model: Model) -> float:
    """Compile (or load from numba's disk cache) the kernels a drop runs; returns the seconds
    it took. Exactly the drop driver's calls (:func:`run_segments`: every segment with a clock,
    the unpowered one with step peaks), so the first drop's ``wall_time_s`` compiles nothing."""
    t0 = time.perf_counter()
    y = levitated_state(model)
    integ = Integrator(model)
    t_out = np.array([0.0, 1e-9, 2e-9])
    Y = np.zeros((3, model.n_state))
    peaks = np.zeros(2 * N_PEAK)
    clock = np.zeros(1)
    integ.advance(y, 0.0, 1e-9, model.controls(True), t_out, Y, 1, None, clock)
    integ.advance(y, 1e-9, 2e-9, model.controls(False), t_out, Y, 2, peaks, clock)
    sampled_diagnostics(model, t_out, Y)
    return time.perf_counter() - t0


def segments(model: Model, t_end: float) -> list[tuple[float, float, bool]]:
    """(start, end, AMB powered) pieces of the run, split exactly at the fault time and at the
    times an event's force jumps or kinks (:func:`event_times`), so that a step boundary meets
    each of them."""
    t_off = model.scene.amb.off_time
    if model.I[F_AMB] == AMB_NONE:
        pieces = [(0.0, t_end, False)]
    elif t_off >= t_end:
        pieces = [(0.0, t_end, True)]
    elif t_off <= 0.0:
        pieces = [(0.0, t_end, False)]
    else:
        pieces = [(0.0, t_off, True), (t_off, t_end, False)]
    for t in event_times(model.scene):
        pieces = [part for a, b, powered in pieces
                  for part in (((a, t, powered), (t, b, powered)) if a < t < b
                               else ((a, b, powered),))]
    return pieces


def event_times(scene) -> tuple[float, ...]:
    """The times the switched-on effects' forces jump or kink: what the effects with a
    ``breaks(scene)`` return (an event's start and end)."""
    return tuple(sorted({t for effect in EFFECTS if hasattr(effect, "breaks")
                         for t in effect.breaks(scene)}))


def run_segments(integ: Integrator, y: np.ndarray, t_end: float, t_out=None, Y=None,
                 bar=None, peaks=None) -> None:
    """Advance ``y`` from t = 0 to ``t_end`` through the AMB-powered/unpowered segments, one
    kernel call per segment, filling ``Y`` at ``t_out[1:]`` if given, and the step-resolved
    maxima after the fault into ``peaks`` if given. A progress ``bar`` follows the time reached
    from this thread while the kernel runs in another one, so the steps (and the numbers) are
    the same with and without it. The drop driver and the environments' fault state both use
    it, so they are bit-identical."""
    model = integ.model
    pos = 1
    for a, b, powered in segments(model, t_end):
        if b <= a:
            continue
        U = model.controls(powered)
        seg_peaks = None if powered else peaks
        if bar is None:             # the clock anyway: one compiled variant with and without bar
            pos = integ.advance(y, a, b, U, t_out, Y, pos, seg_peaks, np.zeros(1))
        else:
            pos = _with_bar(bar, a, lambda clock: integ.advance(y, a, b, U, t_out, Y, pos,
                                                               seg_peaks, clock))


def _with_bar(bar, t0: float, advance):
    """Run ``advance(clock)`` in a worker thread (the kernel releases the GIL) while ``bar``
    follows ``clock[0]``, the time the kernel has reached; returns what ``advance`` returns."""
    clock = np.array([t0])
    with ThreadPoolExecutor(1, thread_name_prefix="drop") as pool:
        job = pool.submit(advance, clock)
        shown = t0
        while True:
            try:
                result = job.result(timeout=BAR_POLL_S)
            except FutureTimeout:
                bar.update(clock[0] - shown)
                shown = clock[0]
                continue
            bar.update(clock[0] - shown)
            return result


def simulate(scene: Scene, t_end: float | None = None, progress: bool = False) -> Result:
    """Simulate a scene from the levitated state to ``t_end`` (default ``solver.t_end``)."""
    if t_end is not None:
        scene = scene.with_overrides({"solver.t_end": t_end})
    model = build_model(scene)
    compile_s = warm_up(model)
    return run_model(model, compile_s, progress)


def run_model(model: Model, compile_s: float = 0.0, progress: bool = False) -> Result:
    """The drop of a built ``model`` whose kernels are loaded (:func:`warm_up`; ``compile_s``:
    the seconds that took, reported apart from the integration's ``wall_time_s``). The single
    drop and the batches of :func:`physics.runs.sweep.run_chunk` both run this, so their numbers are identical."""
    if model.scene.sensor.noise > 0.0:
        raise SceneError(f"sensor.noise = {model.scene.sensor.noise:g} m: the drop driver has no "
                         "noise source (the environments draw its samples); set it to 0")
    t_end = model.scene.solver.t_end
    t_out = output_times(model)
    n_out = len(t_out)
    Y = np.empty((n_out, model.n_state))
    y = levitated_state(model)
    Y[0] = y
    integ = Integrator(model)
    bar = _progress(progress, t_end, model.scene.name)
    peaks = np.zeros(2 * N_PEAK)
    wall0, cpu0 = time.perf_counter(), time.thread_time()
    run_segments(integ, y, t_end, t_out, Y, bar, peaks)
    integ.stats.wall_time_s = time.perf_counter() - wall0
    if bar is None:                 # else the kernel ran in another thread
        integ.stats.cpu_time_s = time.thread_time() - cpu0
    integ.stats.compile_time_s = compile_s
    if bar is not None:
        bar.close()
    Y, aux = sampled_diagnostics(model, t_out, Y)
    t_fault = next((a for a, _, powered in segments(model, t_end) if not powered), None)
    return Result(model, t_out, Y, aux, integ.stats, t_fault,
                  step_peaks=peaks.reshape(2, N_PEAK) if t_fault is not None else None)


def sampled_diagnostics(model: Model, t_out: np.ndarray,
                        Y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The output samples ``Y`` and their per-plane diagnostics (N_AUX columns), both
    column-major (the metrics read time series of single states), each sample's diagnostics with
    the controls of its segment (a sample at the fault time: the unpowered one's)."""
    Y_cols = np.empty(Y.shape, order="F")
    aux = np.empty((len(t_out), N_AUX), order="F")
    block = np.empty((SAMPLE_BLOCK, N_AUX))
    for a, b, powered in segments(model, t_out[-1]):
        i0 = int(np.searchsorted(t_out, a, "left"))
        i1 = int(np.searchsorted(t_out, b, "right")) if powered else len(t_out)
        sample_diagnostics(t_out, Y, i0, i1, model.P, model.I, model.controls(powered), aux,
                           Y_cols, block)
    return Y_cols, aux


def output_times(model: Model) -> np.ndarray:
    """The output sample times of a run (``solver.output_rate`` over ``solver.t_end``); refuses
    (SceneError) an output whose states and diagnostics exceed MAX_OUTPUT_BYTES."""
    sv = model.scene.solver
    n_out = int(round(sv.t_end * sv.output_rate)) + 1
    per_sample = 8 * (model.n_state + N_AUX)
    if n_out * per_sample > MAX_OUTPUT_BYTES:
        raise SceneError(
            f"the output would hold {n_out:,} samples x {model.n_state + N_AUX} values = "
            f"{n_out * per_sample / 1e9:.3g} GB (limit {MAX_OUTPUT_BYTES / 1e9:.3g} GB): lower "
            f"solver.output_rate (now {sv.output_rate:g} Hz, at most "
            f"{int((MAX_OUTPUT_BYTES // per_sample - 1) / sv.t_end)} Hz for this span) or the "
            f"simulated time span (solver.t_end / --t-end, now {sv.t_end:g} s)")
    return np.linspace(0.0, sv.t_end, n_out)


def _progress(enabled: bool, total: float, name: str):
    if not enabled:
        return None
    from tqdm.auto import tqdm
    return tqdm(total=total, desc=f"drop {name}", unit="s sim", bar_format=
                "{l_bar}{bar}| {n:.3f}/{total:.3f} s [{elapsed}<{remaining}]")
