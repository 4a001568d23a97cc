"""Drops in batches (physics.runs.sweep.run_chunk): the numbers of a batch are the single drop's, bit for bit."""
import json

import pytest

from physics import load_scene, simulate
from physics.runs.sweep import run_chunk
from physics.metrics import compute_metrics
from physics.runs.study.observables import drop_observables
from physics.runs.sweep import Outcome, Run

TIMING = ("wall_time_s", "compile_time_s")


def _numbers(metrics: dict) -> str:
    return json.dumps({k: v for k, v in metrics.items() if k not in TIMING}, sort_keys=True)


RUNS = [Run.of("paper", {"solver.t_end": 0.3, "contact.friction": mu, "unbalance.angle_deg": a},
               member=k)
        for k, (mu, a) in enumerate(((0.2, 10.0), (0.5, 200.0), (0.5, 95.0)))]


def test_a_batch_on_two_threads_gives_every_metric_of_the_single_drop_bit_for_bit():
    seen = []
    batch = run_chunk(RUNS + [Run.of("paper", {"contact.friction": 5.0})], drop_observables,
                      threads=2, on_outcome=lambda i, o: seen.append(i))
    assert sorted(seen) == [0, 1, 2, 3]                    # every drop reported as it finished
    for run, o in zip(RUNS, batch):
        single = simulate(load_scene(run.scene, run.settings))
        assert o.ok and o.run == run
        assert _numbers(o.metrics) == _numbers(compute_metrics(single))
        assert o.extra == drop_observables(single)
        assert o.metrics["rhs_evaluations"] > 0 and o.metrics["wall_time_s"] > 0.0
    bad = batch[-1]
    assert not bad.ok and bad.error.startswith("SceneError: contact.friction = 5.0 is out of range")
    # the three drops differ (a batch that returned one drop's numbers thrice would pass above)
    assert len({_numbers(o.metrics) for o in batch[:3]}) == 3


def test_one_thread_and_two_threads_agree_and_outcomes_survive_json():
    one = run_chunk(RUNS[:2], threads=1)
    two = run_chunk(RUNS[:2], threads=2)
    assert [_numbers(o.metrics) for o in one] == [_numbers(o.metrics) for o in two]
    back = Outcome.from_dict(json.loads(json.dumps(two[1].to_dict())))
    assert back.run == two[1].run and _numbers(back.metrics) == _numbers(two[1].metrics)


def test_bad_thread_counts_are_refused_and_an_empty_chunk_is_empty():
    assert run_chunk([]) == []
    for bad in (0, -1, 1.5, True):
        with pytest.raises(ValueError, match="threads must be an integer >= 1"):
            run_chunk(RUNS[:1], threads=bad)


def test_a_progress_bar_changes_no_number_and_the_warm_up_compiles_everything_a_drop_runs():
    """The bar follows a clock the kernel writes (same steps with and without it); after
    warm_up the drop compiles nothing, so its wall_time_s holds no compilation."""
    from physics.integrate import integrate_segment, sample_diagnostics
    from physics.model import build_model
    from physics.simulate import warm_up
    scene = load_scene("paper", {"solver.t_end": 0.15, "contact.friction": 0.5})
    warm_up(build_model(scene))
    kernels = (integrate_segment, sample_diagnostics)
    compiled = [len(k.signatures) for k in kernels]
    plain = compute_metrics(simulate(scene))
    with_bar = compute_metrics(simulate(scene, progress=True))
    assert [len(k.signatures) for k in kernels] == compiled
    assert _numbers(plain) == _numbers(with_bar) and plain["rhs_evaluations"] > 1000


def test_a_drop_after_another_takes_its_arrays_from_the_memory_the_first_one_freed():
    """keep_freed_memory (run_chunk calls it): the next drop's output arrays come from memory
    the previous drop freed, not from fresh pages faulted in one by one (without it each of
    these drops faults in its output arrays again, ~900 pages)."""
    import resource
    from physics.runs.sweep import keep_freed_memory, simulate_drop
    if not keep_freed_memory():
        pytest.skip("the C library has no mallopt (not glibc)")
    simulate_drop(RUNS[0], drop_observables)
    before = resource.getrusage(resource.RUSAGE_THREAD).ru_minflt
    simulate_drop(RUNS[0], drop_observables)
    assert resource.getrusage(resource.RUSAGE_THREAD).ru_minflt - before < 100
