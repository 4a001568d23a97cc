"""The recovery laws tuned like the other designed laws: on a recover suite's validation events,
in their seat, their constants then used by the recover benchmark; the tuned records match the
current environment and sensing."""
import pytest

from agents.benchmarking.recover import ENV_ID, RecoverValidator, tuned_law
from agents.benchmarking.suites import SUITES
from agents.benchmarking.tune_designed import DESIGNED, laws_for, tune_designed
from agents.control.controllers import (SyncPhaseSearch, controller_class, controller_env_kwargs,
                                        with_constants)


def test_recover_suites_tune_the_recovery_laws_on_their_validation_events():
    recover, robust = SUITES.get("recover", "tune"), SUITES.get("robust", "tune")
    assert laws_for(recover) == ["sync-phase-search", "sync-motion-comp"]
    assert not set(laws_for(recover)) & set(laws_for(robust))
    v = recover.validator(ENV_ID)
    assert isinstance(v, RecoverValidator) and v.episodes == 60
    assert list(v.seeds) == list(recover.validation_seeds())
    with pytest.raises(ValueError, match="whirl-brake"):
        tune_designed(recover, ["whirl-brake"], store=False)
    with pytest.raises(ValueError, match="for RotorDrop-Recover-v1"):
        recover.validator("RotorDrop-Full-v1")
    for name in laws_for(recover):          # every tuned constant is one of the law's
        assert set(DESIGNED[name].ranges) <= set(controller_class(name).GAINS)


def test_a_law_with_constants_is_the_law_with_other_class_constants():
    cls = with_constants(SyncPhaseSearch, {"amplitude": 0.5})
    assert cls.name == "sync-phase-search" and cls.GAINS["amplitude"] == 0.5
    assert SyncPhaseSearch.GAINS["amplitude"] == 0.25
    assert cls.GAINS["phases"] == SyncPhaseSearch.GAINS["phases"]
    assert controller_env_kwargs(cls, ENV_ID) == controller_env_kwargs(SyncPhaseSearch, ENV_ID)
    with pytest.raises(TypeError, match="kp"):
        with_constants(SyncPhaseSearch, {"kp": 1.0})


def test_shipped_recover_tunings_match_the_environment_and_are_what_the_benchmark_runs():
    from helpers import check_tuned_records
    suite = SUITES.get("recover", "tune")
    records = check_tuned_records(suite, [61_000, 61_059])
    for name in set(laws_for(suite)) - set(records):      # untuned: the law's own constants
        assert tuned_law(suite, name) is None
    for name, rec in records.items():
        law = tuned_law(suite, name)
        assert all(law.GAINS[k] == v for k, v in rec["gains"].items())
        lo_hi = DESIGNED[name].ranges
        assert all(lo_hi[k][0] <= v <= lo_hi[k][1] for k, v in rec["gains"].items())
    assert tuned_law(suite, "inner-loop") is None              # nothing to tune: its own law
