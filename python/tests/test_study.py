"""``tandem.study``: the simulated study of §III from Python, reduced to a few pairs."""

from __future__ import annotations

import numpy as np
import pytest

import tandem
from conftest import SANDING

SMALL = {"trials": 2, "executions": 6, "samples": 60, "seed": 7}


@pytest.fixture(scope="module")
def study() -> tandem.study.StudyResult:
    return tandem.study.run(SMALL, threads=2)


def test_result_arrays_have_the_documented_shapes(study: tandem.study.StudyResult) -> None:
    assert len(study.trials) == 2
    assert study.t_total_s.shape == study.high_conf_pct.shape == (2, 4)
    for t in study.trials:
        assert t.iteration.tolist() == [0, 1, 2, 3]
        assert t.n_rounds == 3 and t.overlap_ticks.shape == (3,)
        with pytest.warns(DeprecationWarning, match="n_rounds"):
            assert t.n_pairs == 3
        assert len(t.lc_intervals_s) == 4 and all(len(i) == 2 for i in t.lc_intervals_s)
        assert all(s in ("sampled", "completed", "previous", "repaired", "serial", "held", "staggered") for s in t.source)
        assert ((0 <= t.operator_idle_share) & (t.operator_idle_share <= 1)).all()
    assert study.total_overlap_ticks == 0
    assert study.config["trials"] == 2 and study.config["miss_rate"] == 0.01
    assert 0 < study.ground_truth_pct < 100
    assert set(study.phase_times) >= {"alignment_s", "scheduling_s", "simulation_s"}


def test_summary_is_mean_and_sample_std_across_trials(study: tandem.study.StudyResult) -> None:
    s = study.summary
    np.testing.assert_array_equal(s["iteration"], [0, 1, 2, 3])
    np.testing.assert_allclose(s["t_total_mean_s"], study.t_total_s.mean(axis=0), rtol=1e-15)
    np.testing.assert_allclose(s["t_total_std_s"], study.t_total_s.std(axis=0, ddof=1), rtol=1e-12)
    np.testing.assert_allclose(s["high_conf_pct_mean"], study.high_conf_pct.mean(axis=0), rtol=1e-15)


def test_trials_do_not_depend_on_threads_or_on_being_run_alone(
    study: tandem.study.StudyResult,
) -> None:
    one_thread = tandem.study.run(SMALL, threads=1)
    assert one_thread.to_dict()["trials"] == study.to_dict()["trials"]
    alone = tandem.study.run_trial(SMALL, 1)
    assert alone.to_dict() == study.trials[1].to_dict()
    np.testing.assert_array_equal(alone.t_total_s, study.t_total_s[1])


def test_demonstrations_from_a_folder(study: tandem.study.StudyResult) -> None:
    from_folder = tandem.study.run_trial(SMALL, 0, demos_dir=SANDING)
    # The committed CSV files round the generated samples: close, not identical, models.
    assert from_folder.t_total_s.shape == study.trials[0].t_total_s.shape
    assert abs(from_folder.t_total_s[0] - study.trials[0].t_total_s[0]) < 1.0


def test_to_pandas_needs_pandas(study: tandem.study.StudyResult) -> None:
    try:
        import pandas  # noqa: F401
    except ImportError:
        with pytest.raises(ImportError, match="pip install pandas"):
            study.to_pandas()
    else:
        frame = study.to_pandas()
        assert len(frame) == 2 * 4
        assert frame["t_total_s"].tolist() == study.t_total_s.ravel().tolist()


def test_bad_configurations_are_param_errors() -> None:
    with pytest.raises(tandem.ParamError, match="executions"):
        tandem.study.run({"executions": 5})
    with pytest.raises(tandem.ParamError, match="unknown field `trails`"):
        tandem.study.run({"trails": 2})
    cfg = tandem.study.default_config()
    assert (cfg["trials"], cfg["executions"], cfg["samples"]) == (5, 300, 5000)
