"""Bad inputs raise the documented exception with a message naming what and where, and leave
the planner and its state file as they were."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import tandem
from conftest import DEMOS, LABELS, SAMPLES

CHANNELS = ["force", "speed"]


def good(n: int = 30) -> np.ndarray:
    t = np.linspace(0.0, 1.0, n)
    return np.column_stack([np.sin(3 * t), t])


@pytest.mark.parametrize(
    "demo, match",
    [
        ([[1.0, 2.0], [3.0]], "ragged"),
        (good()[:, 0], r"1-D array of shape \(30,\), expected a 2-D array"),
        (np.ones((30, 2, 1)), "3-D array"),
        (good().astype(np.complex128), "dtype complex128"),
        (good() > 0.5, "dtype bool"),
        (np.array([["a", "b"], ["c", "d"]]), "dtype <U1"),
        (np.ones((1, 2)), "1 sample"),
        (np.ones((30, 3)), "3 columns, but channels names 2"),
    ],
)
def test_bad_arrays_are_input_errors_naming_the_argument(demo, match) -> None:
    with pytest.raises(tandem.InputError, match=match) as e:
        tandem.fit([good(), demo], channels=CHANNELS)
    assert e.value.file == "demos[1]"
    assert str(e.value).startswith("demos[1]")


def test_nan_names_the_sample_and_channel() -> None:
    bad = good()
    bad[7, 1] = np.nan
    with pytest.raises(tandem.InputError, match=r"demos\[1\]: sample 7, channel `speed`: non-finite"):
        tandem.fit([good(), bad], channels=CHANNELS)


def test_other_argument_errors() -> None:
    with pytest.raises(tandem.InputError, match="give channels"):
        tandem.fit([good(), good()])
    with pytest.raises(tandem.InputError, match="at least 2"):
        tandem.fit([good()], channels=CHANNELS)
    with pytest.raises(tandem.InputError, match="single value"):
        tandem.fit(good(), channels=CHANNELS)
    with pytest.raises(tandem.InputError, match="single value"):
        tandem.fit(str(DEMOS[0]))


def test_file_errors_carry_file_line_and_column(tmp_path: Path) -> None:
    bad = tmp_path / "bad.csv"
    bad.write_text("force,speed\n1,2\n3,oops\n4,5\n")
    with pytest.raises(tandem.InputError) as e:
        tandem.fit([DEMOS[0], bad])
    assert (e.value.file, e.value.line, e.value.column) == (str(bad), 3, 2)
    assert "not a number: `oops`" in str(e.value)
    with pytest.raises(tandem.InputError, match="cannot read") as e:
        tandem.fit([DEMOS[0], tmp_path / "missing.csv"])
    assert e.value.file == str(tmp_path / "missing.csv")


def test_parameter_errors_name_the_parameter(tmp_path: Path) -> None:
    with pytest.raises(tandem.ParamError, match="unknown field `mu`") as e:
        tandem.fit(DEMOS, params={"confidence": {"mu": 0.1}})
    with pytest.raises(tandem.ParamError) as e:
        tandem.fit(DEMOS, params={"confidence": {"mu_c": 2.0}})
    assert e.value.name == "mu_c"
    with pytest.raises(tandem.ParamError) as e:
        tandem.fit(DEMOS, params={"confidence": {"mu_c": float("nan")}})
    assert e.value.name == "confidence.mu_c"
    toml = tmp_path / "p.toml"
    toml.write_text("[sampler]\nsamples = 0\n")
    with pytest.raises(tandem.ParamError) as e:
        tandem.fit(DEMOS, params=toml)
    assert e.value.name == "samples"


@pytest.mark.parametrize(
    "damage, match",
    [
        (lambda b: b"garbage", "not a tandem state file"),
        (lambda b: b[: len(b) // 2], "truncated state file"),
        (lambda b: b[:-10] + bytes(10), "corrupt state file"),
        (lambda b: b[:8] + (99).to_bytes(4, "little") + b[12:], "state format version 99"),
    ],
)
def test_corrupt_state_files_are_state_file_errors(
    planner: tandem.Planner, tmp_path: Path, damage, match
) -> None:
    path = tmp_path / "cell.tandem"
    planner.save(path)
    path.write_bytes(damage(path.read_bytes()))
    before = path.read_bytes()
    with pytest.raises(tandem.StateFileError, match=match) as e:
        tandem.Planner.load(path)
    assert e.value.path == str(path)
    assert path.read_bytes() == before


def test_missing_and_unwritable_state_files(planner: tandem.Planner, tmp_path: Path) -> None:
    with pytest.raises(tandem.StateFileError, match="cannot"):
        tandem.Planner.load(tmp_path / "missing.tandem")
    with pytest.raises(tandem.StateFileError):
        tandem.Planner.load(tmp_path)
    path = tmp_path / "cell.tandem"
    planner.save(path)
    before = path.read_bytes()
    with pytest.raises(tandem.StateFileError):
        planner.save(tmp_path / "no" / "such" / "folder" / "cell.tandem")
    assert path.read_bytes() == before


def test_a_failed_record_round_leaves_planner_and_file_intact(tmp_path: Path) -> None:
    path = tmp_path / "cell.tandem"
    tandem.fit(DEMOS, params={"sampler": {"samples": SAMPLES}}).save(path)
    before = path.read_bytes()
    planner = tandem.Planner.load(path)
    run = tandem.sim.run_round(planner, tandem.sim.sanding_needs(LABELS, seed=3, planner=planner), seed=3)
    args = run.record_args()
    n = len(args["ref_time_logs"][1])
    bad_cases = [
        ({"supervised": [args["supervised"][0], args["supervised"][1][:-1]]}, tandem.TandemError),
        ({"ref_time_logs": [args["ref_time_logs"][0], args["ref_time_logs"][1][::-1]]}, tandem.InputError),
        ({"ref_time_logs": [args["ref_time_logs"][0], np.full(n, np.nan)]}, tandem.InputError),
        ({"executions": [args["executions"][0], args["executions"][1][:, :-1]]}, tandem.InputError),
        ({"corrected": [args["corrected"][0], args["corrected"][1].astype(float)]}, tandem.InputError),
        ({"executions": args["executions"][:1]}, tandem.InputError),
    ]
    for change, error in bad_cases:
        with pytest.raises(error):
            planner.record_round(**{**args, **change})
        assert planner.rounds_recorded == 0
    planner.save(tmp_path / "after.tandem")
    assert (tmp_path / "after.tandem").read_bytes() == before
    assert path.read_bytes() == before
    # The good round still records.
    planner.record_round(**args)
    assert planner.rounds_recorded == 1


def test_the_two_robot_names_are_deprecated_aliases(tmp_path: Path) -> None:
    """``record_pair`` and ``pairs_recorded`` (kept one release) warn and do what
    ``record_round`` and ``rounds_recorded`` do: the same state file, byte for byte."""
    fitted = tandem.fit(DEMOS, params={"sampler": {"samples": SAMPLES}})
    fitted.save(tmp_path / "base.tandem")
    new, old = (tandem.Planner.load(tmp_path / "base.tandem") for _ in range(2))
    run = tandem.sim.run_round(new, tandem.sim.sanding_needs(LABELS, seed=4, planner=new), seed=4)
    new.record_round(**run.record_args())
    with pytest.warns(DeprecationWarning, match="use Planner.record_round"):
        old.record_pair(**run.record_args())
    with pytest.warns(DeprecationWarning, match="use Planner.rounds_recorded"):
        assert old.pairs_recorded == 1
    assert new.rounds_recorded == old.rounds_recorded == 1
    new.save(tmp_path / "new.tandem")
    old.save(tmp_path / "old.tandem")
    assert (tmp_path / "new.tandem").read_bytes() == (tmp_path / "old.tandem").read_bytes()


def test_a_header_only_file_is_located_by_path_and_line(tmp_path: Path) -> None:
    """The file field is the path itself and the line is set (it was ``"…csv:1:1"`` with
    ``line`` None)."""
    header_only = tmp_path / "header_only.csv"
    header_only.write_text("t,force,speed\n")
    with pytest.raises(tandem.InputError, match="0 sample") as e:
        tandem.fit([DEMOS[0], header_only])
    assert e.value.file == str(header_only)
    assert (e.value.line, e.value.column) == (1, 1)
    assert str(e.value).startswith(f"{header_only}:1:1: ")
