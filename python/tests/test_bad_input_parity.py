"""The command line's bad-input catalogue (crates/tandem-cli/tests/bad_input.rs) run through
Python too: every case that has a Python path fails in Python with the message the command
line prints (docs/python.md: both front ends run the same checks).

Each case runs the command line (``$TANDEM_CLI``) on the same files and arguments as the Rust
catalogue, expects exit code 2, and compares:

* ``same``: the library's message. Python's ``str(e)`` appears whole in the command line's
  ``error:`` line (the command line may put its context before it, e.g. ``cannot fit: …``);
* ``tail``: the same message with the location written per front end: the command line names
  the file and line of a CSV it parsed, Python the argument and sample index of the array it
  was given; the text after the location is the same;
* ``worded``: a check of the front end's own arguments (a flag there, a keyword here), worded
  for each: both messages name the listed facts.

``NO_PYTHON_PATH`` lists the catalogue's cases that Python cannot express, with the reason.
"""

from __future__ import annotations

import subprocess
import warnings
from pathlib import Path
from typing import Callable, Iterable, List, Sequence

import numpy as np
import pytest

import tandem
from conftest import cli

# The small task of crates/tandem-cli/tests/common/mod.rs, written the same way.
SMALL_N_REF = 60


def small_demo(n: int, bump: float) -> str:
    """``common::small_demo``: time ``t`` (10 ms), position ``x`` and ``force`` with a bump of
    height ``bump`` over the middle third."""
    rows = ["t,x,force"]
    for k in range(n):
        u = k / (n - 1)
        f = 5.0 + bump if 1.0 / 3.0 <= u < 2.0 / 3.0 else 5.0
        rows.append(f"{k * 0.01:.2f},{u:.6f},{f:.4f}")
    return "\n".join(rows) + "\n"


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.write_text(text)
    return path


def small_demos(folder: Path) -> List[Path]:
    return [
        write(folder, f"demo_{i}.csv", small_demo(n, bump))
        for i, (n, bump) in enumerate([(SMALL_N_REF, 0.0), (66, 6.0), (56, 12.0)])
    ]


def small_execution(folder: Path, stem: str) -> List[Path]:
    """``common::small_execution``: demo 0 replayed at reference speed, every sample
    supervised, none corrected: (execution, log, corrections) files."""
    exe = write(folder, f"{stem}.csv", small_demo(SMALL_N_REF, 0.0))
    log = write(folder, f"{stem}.reflog.csv",
                "ref_sample\n" + "".join(f"{k}\n" for k in range(SMALL_N_REF)))
    corr = write(folder, f"{stem}.corr.csv", "supervised,corrected\n" + "1,0\n" * SMALL_N_REF)
    return [exe, log, corr]


def read_log(path: Path) -> np.ndarray:
    return np.loadtxt(path, skiprows=1, ndmin=1)


def read_flags(path: Path):
    flags = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2).astype(bool)
    return flags[:, 0], flags[:, 1]


def run_cli(args: Iterable[object]) -> subprocess.CompletedProcess:
    return subprocess.run([str(cli()), *map(str, args)], capture_output=True, text=True,
                          check=False)


def cli_error(args: Sequence[object]) -> str:
    """The command line's error message (exit code 2, after the notes)."""
    out = run_cli(args)
    assert out.returncode == 2, f"{args}: exit {out.returncode}\n{out.stderr}"
    lines = [line for line in out.stderr.splitlines() if not line.startswith("note: ")]
    assert lines and lines[0].startswith("error: "), out.stderr
    assert "panicked" not in out.stderr
    return "\n".join(lines)[len("error: "):]


def py_error(call: Callable[[], object], exc: type = tandem.TandemError) -> str:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tandem.DataWarning)
        with pytest.raises(exc) as e:
            call()
    return str(e.value)


def assert_same(cli_msg: str, py_msg: str) -> None:
    assert py_msg in cli_msg, f"\n  python: {py_msg}\n  cli:    {cli_msg}"


def assert_tail(cli_msg: str, py_msg: str, marker: str) -> None:
    """Both messages hold ``marker`` and the same text from it on."""
    assert marker in cli_msg and marker in py_msg, f"\n  python: {py_msg}\n  cli:    {cli_msg}"
    assert cli_msg[cli_msg.index(marker):] == py_msg[py_msg.index(marker):], (
        f"\n  python: {py_msg}\n  cli:    {cli_msg}"
    )


def assert_worded(cli_msg: str, py_msg: str, facts: Sequence[str]) -> None:
    for fact in facts:
        assert fact in cli_msg and fact in py_msg, (
            f"`{fact}`\n  python: {py_msg}\n  cli:    {cli_msg}"
        )


#: Cases of bad_input.rs with no Python equivalent, and why.
NO_PYTHON_PATH = {
    # malformed_executions: Python takes logs and flags as arrays, not files, so the CSV
    # parsing of `--log` and `--corrections` files is the command line's alone.
    "wrong_col.reflog.csv": "a `--log` file's columns (Python: a log is an array)",
    "nan.reflog.csv": "parsing a `--log` file (Python: NumPy parses, a NaN is refused as an "
                      "array value, tested in test_data_checks.py)",
    "decreasing.reflog.csv": "the `--log` file reader's line number (Python: the same rule "
                             "from the library, tested below without a line)",
    "two.corr.csv": "a `--corrections` field other than 0/1 (Python: flags are booleans)",
    "ragged.corr.csv": "a ragged `--corrections` file",
    "empty.corr.csv": "an empty `--corrections` file",
    "header_only.reflog.csv": "a `--log` file with a header only",
    # fit
    "--ranges": "`--ranges NAME=VALUE` is the command line's syntax for params['fit']['ranges']",
    "--no-holds --hold-at": "two flags that contradict each other; Python has one `holds=`",
    "--hold-at abc": "a flag value that is not a number; Python's holds=['abc'] is a rule",
    # other commands
    "plot -o FILE": "plotting is the command line's (Python returns arrays)",
    "simulate --rounds/--miss-rate/--channel/--write": "flags of `tandem simulate`'s loop; "
        "tandem.sim.run_round runs one round and writes nothing",
    "need --from-labels/--column/--level, -o exists": "`tandem need`'s label files and output "
        "file; tandem.sim.needs takes regions, levels or a need file and writes nothing",
}


@pytest.fixture()
def folder(tmp_path: Path) -> Path:
    return tmp_path


# --- malformed_demonstrations ---------------------------------------------------------

def rows_of(text: str, keep: Callable[[int], bool]) -> str:
    return "".join(f"{line}\n" for k, line in enumerate(text.splitlines()) if keep(k))


def retimed(n: int, period: float) -> str:
    lines = small_demo(n, 1.0).splitlines()
    out = [lines[0]]
    for k, line in enumerate(lines[1:]):
        out.append(f"{k * period},{line.split(',', 1)[1]}")
    return "\n".join(out) + "\n"


BAD_DEMOS = {
    "empty.csv": "",
    "header_only.csv": "t,x,force\n",
    "ragged.csv": "t,x,force\n0.00,0,5\n0.01,0.5\n0.02,1,5\n",
    "text.csv": "t,x,force\n0.00,0,5\n0.01,0.5,five\n0.02,1,5\n",
    "nan.csv": "t,x,force\n0.00,0,5\n0.01,NaN,5\n0.02,1,5\n",
    "inf.csv": "t,x,force\n0.00,0,5\n0.01,0.5,inf\n0.02,1,5\n",
    "huge.csv": "t,x,force\n0.00,0,5\n0.01,1e308,5\n0.02,1,5\n",
    "time_back.csv": "t,x,force\n0.00,0,5\n0.02,0.5,5\n0.01,1,5\n",
    "other_channels.csv": small_demo(50, 1.0).replace("t,x,force", "t,x,torque"),
    "semicolons.csv": "t;x;force\n0.00;0;5\n0.01;0.5;5\n0.02;1;5\n",
    "decimal_comma.csv": "t;x;force\n0,00;0;5\n0,01;0,5;5\n0,02;1;5\n",
    "tabs.csv": "t\tx\tforce\n0.00\t0\t5\n0.01\t0.5\t5\n0.02\t1\t5\n",
    "dropped.csv": rows_of(small_demo(60, 1.0), lambda k: k != 30),
    "rate.csv": retimed(40, 0.02),
    "dup_header.csv": "t,x,x\n0.00,0,5\n0.01,0.5,5\n",
    "bad.json": '{"channels": ["x", "force"], "samples": [[0, 1], [2]]}',
    "time_col.csv": small_demo(60, 1.0).replace("t,x,force", "time,x,force"),
    "stamp_col.csv": small_demo(60, 1.0).replace("t,x,force", "x,force,t_ms"),
    "short.csv": small_demo(20, 1.0),
    "long.csv": small_demo(130, 1.0),
}


@pytest.mark.parametrize("name", sorted(BAD_DEMOS))
def test_malformed_demonstrations(folder: Path, name: str) -> None:
    demos = small_demos(folder)
    bad = write(folder, name, BAD_DEMOS[name])
    out = folder / "out.tandem"
    cli_msg = cli_error(["fit", *demos, bad, "--samples", 50, "-o", out])
    py_msg = py_error(lambda: tandem.fit([*demos, bad], params={"sampler": {"samples": 50}}),
                      tandem.InputError)
    assert_same(cli_msg, py_msg)
    assert str(bad) in py_msg
    assert not out.exists()


def test_half_a_demonstration_is_refused_the_same_way(folder: Path) -> None:
    # A demonstration cut off half way is refused by the library (issue 39, item 2), so both
    # front ends say the same thing about it.
    demos = small_demos(folder)
    half = write(folder, "half.csv", rows_of(small_demo(60, 1.0), lambda k: k <= 30))
    cli_msg = cli_error(["fit", *demos, half, "--samples", 50, "-o", folder / "out.tandem"])
    py_msg = py_error(
        lambda: tandem.fit([*demos, half], params={"sampler": {"samples": 50}}),
        tandem.InputError,
    )
    assert_worded(cli_msg, py_msg, ["does not reach the end of the task", str(half)])
    assert not (folder / "out.tandem").exists()


def test_a_demonstration_off_its_grid_is_resampled_or_refused_the_same_way(folder: Path) -> None:
    demos = small_demos(folder)
    params = {"sampler": {"samples": 50}}
    out = folder / "out.tandem"
    # A gap of five rows is too long to resample: the same refusal from both front ends.
    gap = write(folder, "gap.csv", rows_of(small_demo(60, 1.0), lambda k: not 20 <= k < 25))
    cli_msg = cli_error(["fit", *demos, gap, "--resample", "--samples", 50, "-o", out])
    py_msg = py_error(lambda: tandem.fit([*demos, gap], params=params, resample=True),
                      tandem.InputError)
    assert_same(cli_msg, py_msg)
    assert "a gap of 0.06 s" in py_msg and not out.exists()
    # One dropped row: refused without resample=, naming it; put back on the grid with it.
    dropped = write(folder, "dropped_ok.csv", rows_of(small_demo(60, 1.0), lambda k: k != 30))
    with pytest.raises(tandem.InputError, match=r"resample=True. of Python's .fit."):
        tandem.fit([*demos, dropped], params=params)
    with pytest.warns(tandem.DataWarning) as caught:
        planner = tandem.fit([*demos, dropped], params=params, resample=True)
    said = [str(w.message) for w in caught]
    assert any(m.startswith(f"{dropped}: resampled 59 rows") and "onto 60 samples 0.01 s apart" in m
               for m in said), said
    assert planner.model.n_ref > 0
    model = tandem.fit_model([*demos, dropped], resample=True)
    assert model.n_ref == planner.model.n_ref
    # Arrays carry no row times to resample.
    arrays = [np.array([[k * 0.01, 5.0] for k in range(60)]) for _ in range(2)]
    with pytest.raises(tandem.InputError, match="resample=True needs the time of every row"):
        tandem.fit(arrays, channels=["x", "force"], dt_s=0.01, resample=True)


def test_drifting_loggers_go_onto_one_grid_and_the_suggested_period_works(folder: Path) -> None:
    """Loggers at 97 and 103 Hz beside three at 100 Hz: ``resample=True`` puts every file onto
    the period most of them share, in one note, as ``tandem fit --resample`` does; a file at
    twice the period is another rate, refused by both front ends with the period to give, and
    giving it (``resample=True, dt_s=0.01``, the message's own fix) then fits."""
    demos = small_demos(folder)
    params = {"sampler": {"samples": 50}}
    slow = write(folder, "drift_slow.csv", retimed(60, 0.0103))
    fast = write(folder, "drift_fast.csv", retimed(60, 0.0097))
    with pytest.warns(tandem.DataWarning) as caught:
        planner = tandem.fit([*demos, slow, fast], params=params, resample=True)
    said = [str(w.message) for w in caught]
    assert any("the 5 files' logger periods differ by up to 6.0 % (0.009708738 – 0.010309278 s"
               in m and "every file resampled onto 0.01 s, the period of 3 of them" in m
               for m in said), said
    assert planner.model.dt_s == pytest.approx(0.01, rel=1e-12)
    out = folder / "out.tandem"
    ok = run_cli(["fit", *demos, slow, fast, "--resample", "--samples", 50, "-o", out])
    assert ok.returncode == 0, ok.stderr
    assert "every file resampled onto 0.01 s, the period of 3 of them" in ok.stderr
    double = write(folder, "double.csv", retimed(60, 0.02))
    cli_msg = cli_error(["fit", *demos, double, "--resample", "--samples", 50, "-o",
                         folder / "other.tandem"])
    py_msg = py_error(lambda: tandem.fit([*demos, double], params=params, resample=True),
                      tandem.InputError)
    assert_same(cli_msg, py_msg)
    assert "resample=True, dt_s=0.01" in py_msg
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tandem.DataWarning)
        fitted = tandem.fit([*demos, double], params=params, resample=True, dt_s=0.01)
    assert fitted.model.dt_s == pytest.approx(0.01, rel=1e-12)


def test_a_period_that_contradicts_the_file(folder: Path) -> None:
    demos = small_demos(folder)
    cli_msg = cli_error(["fit", *demos, "--dt", 0.02, "-o", folder / "out.tandem"])
    py_msg = py_error(lambda: tandem.fit(demos, dt_s=0.02), tandem.ParamError)
    # `--dt` there, `dt_s` here.
    assert_worded(cli_msg, py_msg, ["0.02 s", "0.01 s", str(demos[0])])


def test_a_zero_quaternion_names_its_line(folder: Path) -> None:
    def quat_demo(n: int, zero_at) -> str:
        rows = ["t,x,qx,qy,qz,qw"]
        for k in range(n):
            q = "0,0,0,0" if k == zero_at else "0,0,0,1"
            rows.append(f"{k * 0.01:.2f},{k / n},{q}")
        return "\n".join(rows) + "\n"

    demos = [write(folder, f"quat_{i}.csv", quat_demo(50 + i, 20 if i == 2 else None))
             for i in range(3)]
    cli_msg = cli_error(["fit", *demos, "--samples", 50, "-o", folder / "out.tandem"])
    py_msg = py_error(lambda: tandem.fit(demos), tandem.InputError)
    assert_same(cli_msg, py_msg)
    assert f"{demos[2]}:22" in py_msg


def test_a_missing_file_and_a_single_demonstration(folder: Path) -> None:
    demos = small_demos(folder)
    missing = folder / "missing.csv"
    out = folder / "out.tandem"
    assert_same(cli_error(["fit", missing, *demos[1:], "-o", out]),
                py_error(lambda: tandem.fit([missing, *demos[1:]]), tandem.InputError))
    # The number of demonstrations is an argument check of each front end.
    assert_worded(cli_error(["fit", demos[0], "-o", out]),
                  py_error(lambda: tandem.fit([demos[0]]), tandem.InputError),
                  ["demonstration", "at least 2"])


# --- channel_sets_the_model_rejects ---------------------------------------------------

@pytest.mark.parametrize("header, pad", [("t,x,rate", ""), ("t,x,qx,qy,qz", ",0,0")])
def test_channel_sets_the_model_rejects(folder: Path, header: str, pad: str) -> None:
    demos = []
    for i in range(2):
        lines = small_demo(50 + 5 * i, 2.0 * i).splitlines()
        text = "".join(f"{header if k == 0 else line + pad}\n" for k, line in enumerate(lines))
        demos.append(write(folder, f"demo_{i}.csv", text))
    cli_msg = cli_error(["fit", *demos, "-o", folder / "out.tandem"])
    assert_same(cli_msg, py_error(lambda: tandem.fit(demos), tandem.InputError))


# --- bad_parameters_and_outputs -------------------------------------------------------

# (text, facts): `None` when the parameter crate's message is the same on both sides (the
# command line adds the file before it: `range.toml: invalid parameter: …`; Python's
# ParamError names the parameter in `.name` and not the file it came from); facts when the
# TOML reader's text differs (the command line condenses it to `file:line: what`, Python
# keeps the toml crate's multi-line excerpt).
PARAM_FILES = {
    "range.toml": ("[confidence]\nsigma2_max = 0.3\n", None),
    "unknown.toml": ("[confidence]\ngamma_q = 1.0\n", ["gamma_q", "unknown field"]),
    "syntax.toml": ("[sampler\nsamples = 10\n", []),
    "type.toml": ("[sampler]\nsamples = \"many\"\n",
                  ['invalid type: string "many", expected usize']),
    "len.toml": ("[fit]\nranges = [1.0, 2.0]\n", None),
}


@pytest.mark.parametrize("name", sorted(PARAM_FILES))
def test_bad_parameter_files(folder: Path, name: str) -> None:
    text, facts = PARAM_FILES[name]
    demos = small_demos(folder)
    params = write(folder, name, text)
    cli_msg = cli_error(["fit", *demos, "--params", params, "-o", folder / "out.tandem"])
    py_msg = py_error(lambda: tandem.fit(demos, params=params), tandem.ParamError)
    if facts is None:
        assert_same(cli_msg, py_msg)
        assert str(params) in cli_msg
    else:
        assert_worded(cli_msg, py_msg, [str(params), *facts])


def test_bad_parameter_values_and_outputs(folder: Path) -> None:
    demos = small_demos(folder)
    out = folder / "out.tandem"
    assert_same(cli_error(["fit", *demos, "--samples", 0, "-o", out]),
                py_error(lambda: tandem.fit(demos, params={"sampler": {"samples": 0}}),
                         tandem.ParamError))
    assert_worded(cli_error(["fit", *demos, "--dt=-1", "-o", out]),
                  py_error(lambda: tandem.fit(demos, dt_s=-1.0), tandem.ParamError),
                  ["-1"])
    planner = tandem.fit(demos, params={"sampler": {"samples": 50}})
    before = demos[2].read_bytes()
    assert_same(cli_error(["fit", *demos, "--samples", 50, "-o", demos[2]]),
                py_error(lambda: planner.save(demos[2]), tandem.StateFileError))
    assert demos[2].read_bytes() == before
    # A folder: the command line's own check ("is a folder; give a file name for the
    # output") before the library's ("refusing to overwrite: it is a folder").
    assert_worded(cli_error(["fit", *demos, "--samples", 50, "-o", folder]),
                  py_error(lambda: planner.save(folder), tandem.StateFileError),
                  [str(folder), "is a folder"])
    # Into a folder that does not exist, or under a file: the command line checks the target
    # first ("folder … does not exist or is not a folder"), Planner.save names the folder and
    # the fix ("…: cannot save the state file there: the folder does not exist: create it
    # first …" / "it is a file, not a folder …"). Both refuse; nothing is written.
    for target, why in ((folder / "no/such/folder/cell.tandem", "the folder does not exist"),
                        (demos[0] / "cell.tandem", "it is a file, not a folder")):
        assert_worded(cli_error(["fit", *demos, "--samples", 50, "-o", target]),
                      py_error(lambda: planner.save(target), tandem.StateFileError),
                      [str(target.parent)])
        assert why in py_error(lambda: planner.save(target), tandem.StateFileError)
    assert not (folder / "no").exists() and demos[0].is_file()


# --- bad_hold_declarations ------------------------------------------------------------

@pytest.mark.parametrize("flag, value, holds, kind", [
    ("--hold-where", "torque<3", ["torque<3"], "same"),
    ("--hold-where", "force=3", ["force=3"], "tail"),
    ("--hold-where", "force<", ["force<"], "tail"),
    ("--hold-where", "force>1e9", ["force>1e9"], "same"),
    ("--hold-at", "100", [100.0], "same"),
    ("--hold-at", "-1", [-1.0], "worded"),
    ("--hold-at", "nan", [float("nan")], "worded"),
])
def test_bad_hold_declarations(folder: Path, flag, value, holds, kind) -> None:
    demos = small_demos(folder)
    cli_msg = cli_error(["fit", *demos, "--samples", 50, "-o", folder / "out.tandem",
                         flag, value])
    py_msg = py_error(lambda: tandem.fit(demos, params={"sampler": {"samples": 50}},
                                         holds=holds), tandem.ParamError)
    if kind == "same":
        assert_same(cli_msg, py_msg)
    elif kind == "tail":
        # clap's `invalid value 'force=3' for '--hold-where <RULE>': …` there, `holds[0]: …`
        # here, the parser's message after it.
        assert py_msg.startswith("holds[0]: ")
        assert_same(cli_msg, py_msg[len("holds[0]: "):])
    else:
        # The command line checks its flag's number itself.
        assert_worded(cli_msg, py_msg, [value.replace("nan", "NaN") if value == "nan" else value])


def test_a_hold_rule_without_comparison_in_a_parameter_file(folder: Path) -> None:
    demos = small_demos(folder)
    params = write(folder, "rule.toml", "[holds]\nrules = [\"force\"]\n")
    cli_msg = cli_error(["fit", *demos, "--samples", 50, "-o", folder / "out.tandem",
                         "--params", params])
    py_msg = py_error(lambda: tandem.fit(demos, params=params), tandem.ParamError)
    assert_worded(cli_msg, py_msg, [str(params), "no comparison"])


# --- damaged_state_files --------------------------------------------------------------

def small_state(folder: Path) -> Path:
    state = folder / "cell.tandem"
    # Demo 0 is the reference, as in the CLI tests' `common::small_state` (the executions
    # below replay demo 0 on its own axis; the default reference is the medoid).
    out = run_cli(["fit", *small_demos(folder), "--reference", "first", "--samples", 200, "-o", state])
    assert out.returncode == 0, out.stderr
    return state


def damaged(good: bytes) -> dict:
    corrupt = bytearray(good)
    corrupt[-10] ^= 0xFF
    version = bytearray(good)
    version[8:12] = (99).to_bytes(4, "little")
    return {
        "truncated.tandem": good[: len(good) // 2],
        "short_header.tandem": good[:12],
        "corrupt.tandem": bytes(corrupt),
        "version.tandem": bytes(version),
        "trailing.tandem": good + b"junk",
        "text.tandem": b"t,x,force\n1,2,3\n",
        "empty.tandem": b"",
    }


def test_damaged_state_files(folder: Path) -> None:
    state = small_state(folder)
    for name, data in damaged(state.read_bytes()).items():
        path = folder / name
        path.write_bytes(data)
        cli_msg = cli_error(["inspect", path, "--json"])
        py_msg = py_error(lambda: tandem.Planner.load(path), tandem.StateFileError)
        assert_same(cli_msg, py_msg)
        assert path.read_bytes() == data
    missing = folder / "missing.tandem"
    assert_same(cli_error(["inspect", missing]),
                py_error(lambda: tandem.Planner.load(missing), tandem.StateFileError))
    # A folder: "is a folder, not a state file" on the command line (its own check) and from
    # Planner.load; both name the folder.
    assert_worded(cli_error(["schedule", folder]),
                  py_error(lambda: tandem.Planner.load(folder), tandem.StateFileError),
                  [str(folder), "is a folder, not a state file"])
    planner = tandem.Planner.load(state)
    assert_worded(cli_error(["schedule", state, "--samples", 0]),
                  py_error(lambda: planner.reschedule(samples=0), tandem.ParamError),
                  ["samples"])


# --- malformed_executions -------------------------------------------------------------

def record_cli(state: Path, a: Sequence[Path], b: Sequence[Path], *extra) -> List[object]:
    args: List[object] = ["record", state]
    for e in (a, b):
        for flag, path in zip(("--execution", "--log", "--corrections"), e):
            args += [flag, path]
    return args + list(extra)


def record_py(planner: tandem.Planner, a: Sequence, b: Sequence, **kw) -> Callable[[], object]:
    """`record_round` with robot executions given as (execution path, log array, supervised
    array, corrected array)."""
    def call():
        return planner.record_round(
            executions=[a[0], b[0]],
            ref_time_logs=[a[1], b[1]],
            supervised=[a[2], b[2]],
            corrected=[a[3], b[3]],
            **kw,
        )
    return call


def as_arrays(files: Sequence[Path]) -> list:
    sup, cor = read_flags(files[2])
    return [files[0], read_log(files[1]), sup, cor]


def test_malformed_executions(folder: Path) -> None:
    state = small_state(folder)
    planner = tandem.Planner.load(state)
    n = SMALL_N_REF
    good_a, good_b = small_execution(folder, "a"), small_execution(folder, "b")
    arrays_a, arrays_b = as_arrays(good_a), as_arrays(good_b)
    before = state.read_bytes()

    def both(files_a, arrays, check) -> None:
        for cli_args, py_call in (
            (record_cli(state, files_a, good_b), record_py(planner, arrays, arrays_b)),
            (record_cli(state, good_b, files_a), record_py(planner, arrays_b, arrays)),
        ):
            check(cli_error(cli_args), py_error(py_call, tandem.InputError))
            assert state.read_bytes() == before
            assert planner.rounds_recorded == 0

    # A corrected sample that was not supervised: the library's rule (check_execution),
    # located at the file's line there and at the array's sample here.
    corr = write(folder, "unsupervised.corr.csv",
                 "supervised,corrected\n0,1\n" + "1,0\n" * (n - 1))
    sup, cor = read_flags(corr)
    def located_tail(c: str, p: str) -> None:
        assert_tail(c, p, "`corrected` is 1 but `supervised` is 0")
        assert f"{corr}:2: " in c and "sample 0: " in p, (c, p)

    both([good_a[0], good_a[1], corr], [good_a[0], arrays_a[1], sup, cor], located_tail)
    # Fewer flags than samples: counted in rows of the file there, entries here.
    short = write(folder, "short.corr.csv", "supervised,corrected\n" + "1,0\n" * (n - 5))
    sup, cor = read_flags(short)
    both([good_a[0], good_a[1], short], [good_a[0], arrays_a[1], sup, cor],
         lambda c, p: assert_worded(c, p, ["55", "60 samples"]))
    # Logs the library refuses: outside the task, stuck at its start, starting late.
    for name, log in {
        "outside.reflog.csv": [2 * k for k in range(n)],
        "stuck.reflog.csv": [0] * n,
        "late.reflog.csv": [min(k + 5, 59) for k in range(n)],
    }.items():
        path = write(folder, name, "ref_sample\n" + "".join(f"{v}\n" for v in log))
        both([good_a[0], path, good_a[2]], [good_a[0], np.array(log, float), *arrays_a[2:]],
             lambda c, p: assert_tail(c, p, p.split(": ", 1)[1] if ": " in p else p))
    # Executions the model refuses: other channels, text in a number, a time column named
    # otherwise, a 1 kHz file taken for one sample per 10 ms tick.
    fast_rows = 10 * (n - 1) + 1
    fast_text = small_demo(fast_rows, 0.0).splitlines()
    fast = write(folder, "fast.csv", "\n".join(
        [fast_text[0].split(",", 1)[1]] + [r.split(",", 1)[1] for r in fast_text[1:]]) + "\n")
    fast_log = write(folder, "fast.reflog.csv",
                     "ref_sample\n" + "".join(f"{k / 10}\n" for k in range(fast_rows)))
    fast_corr = write(folder, "fast.corr.csv", "supervised,corrected\n" + "1,0\n" * fast_rows)
    for files in (
        [write(folder, "channels.csv",
               small_demo(n, 0.0).replace("t,x,force", "t,x,torque")), good_a[1], good_a[2]],
        [write(folder, "text.csv", small_demo(n, 0.0).replace("5.0000", "high", 1)),
         good_a[1], good_a[2]],
        [write(folder, "stamped.csv",
               small_demo(n, 0.0).replace("t,x,force", "stamp,x,force")), good_a[1], good_a[2]],
        [fast, fast_log, fast_corr],
    ):
        both(files, as_arrays(files), assert_same)
    # One execution for two robots: each front end's argument.
    one = record_cli(state, good_a, good_b)[:8]
    assert_worded(cli_error(one),
                  py_error(lambda: planner.record_round([good_a[0]], [arrays_a[1]],
                                                        [arrays_a[2]], [arrays_a[3]]),
                           tandem.InputError),
                  ["2"])
    # The same round twice.
    assert run_cli(record_cli(state, good_a, good_b)).returncode == 0
    planner.record_round(**{
        "executions": [good_a[0], good_b[0]], "ref_time_logs": [arrays_a[1], arrays_b[1]],
        "supervised": [arrays_a[2], arrays_b[2]], "corrected": [arrays_a[3], arrays_b[3]],
    })
    assert_same(cli_error(record_cli(state, good_b, good_a)),
                py_error(record_py(planner, arrays_b, arrays_a), tandem.InputError))


def test_an_execution_off_its_grid_and_a_json_one_to_resample(folder: Path) -> None:
    state = small_state(folder)
    planner = tandem.Planner.load(state)
    n = SMALL_N_REF
    good_b = small_execution(folder, "b")
    other = write(folder, "other.csv", small_demo(n, 0.5))
    other_b = [other, good_b[1], good_b[2]]
    exe, log, corr = ["t,x,force"], ["ref_sample"], ["supervised,corrected"]
    last = 148
    for k in (k for k in range(last + 1) if k != 80):
        late = 0.0011 if k % 7 == 3 and k != last else 0.0
        t = 0.004 * k + late
        r = min(100.0 * t, n - 1)
        exe.append(f"{t:.4f},{r / (n - 1):.6f},5.0000")
        log.append(f"{r:.4f}")
        corr.append(f"1,{int(k == 60)}")
    stamped = [write(folder, f"stamped_250.{s}csv", "\n".join(x) + "\n")
               for s, x in (("", exe), ("reflog.", log), ("corr.", corr))]
    assert_same(cli_error(record_cli(state, stamped, other_b)),
                py_error(record_py(planner, as_arrays(stamped), as_arrays(other_b)),
                         tandem.InputError))
    js = write(folder, "exec.json", '{"channels":["x","force"],"samples":[[0,5],[1,5]]}')
    good_a = small_execution(folder, "a")
    arrays = as_arrays(good_a)
    arrays[0] = js
    assert_worded(cli_error(record_cli(state, [js, *good_a[1:]], good_b, "--resample")),
                  py_error(record_py(planner, arrays, as_arrays(good_b), resample=True),
                           tandem.InputError),
                  [str(js), "applies to CSV files"])


# --- need files and requests, a schedule at another tick -------------------------------

NEED_FILES = {
    "short.csv": "need\n" + "0.5\n" * (SMALL_N_REF - 1),
    "prob.csv": "need\n1.5\n" + "0.5\n" * (SMALL_N_REF - 1),
    "region.csv": "need,region\n0.5,1\n0.2,1\n" + "0.5,2\n" * (SMALL_N_REF - 2),
    "nocol.csv": "p\n" + "0.5\n" * SMALL_N_REF,
}


def test_malformed_need_files(folder: Path) -> None:
    state = small_state(folder)
    planner = tandem.Planner.load(state)
    for name, text in NEED_FILES.items():
        need = write(folder, name, text)
        cli_msg = cli_error(["simulate", state, "--need", need, "--rounds", 1])
        py_msg = py_error(lambda: tandem.sim.needs(need_file=need, planner=planner),
                          tandem.InputError)
        assert_same(cli_msg, py_msg)


@pytest.mark.parametrize("region, regions", [
    ("0.2-0.1=0.5", [(0.2, 0.1, 0.5)]),
    ("0.1-0.2=1.5", [(0.1, 0.2, 1.5)]),
    ("0.1-9=0.5", [(0.1, 9.0, 0.5)]),
])
def test_bad_need_regions(folder: Path, region: str, regions) -> None:
    state = small_state(folder)
    planner = tandem.Planner.load(state)
    cli_msg = cli_error(["need", state, "--region", region, "-o", folder / "need.csv"])
    py_msg = py_error(lambda: tandem.sim.needs(regions, planner=planner))
    assert_same(cli_msg, py_msg)


def test_overlapping_need_regions(folder: Path) -> None:
    state = small_state(folder)
    planner = tandem.Planner.load(state)
    cli_msg = cli_error(["need", state, "--region", "0.1-0.3=0.5", "--region", "0.2-0.4=0.5",
                         "-o", folder / "need.csv"])
    py_msg = py_error(lambda: tandem.sim.needs([(0.1, 0.3, 0.5), (0.2, 0.4, 0.5)],
                                               planner=planner))
    assert_same(cli_msg, py_msg)


def test_a_schedule_checked_at_another_tick_is_not_simulated(folder: Path) -> None:
    demos = small_demos(folder)
    params = write(folder, "half_tick.toml",
                   "[fit]\nreference = \"first\"\n[sampler]\nsamples = 200\ntick_s = 0.005\n")
    state = folder / "cell.tandem"
    assert run_cli(["fit", *demos, "--params", params, "-o", state]).returncode == 0
    need = write(folder, "need.csv", "need\n" + "0.5\n" * SMALL_N_REF)
    cli_msg = cli_error(["simulate", state, "--need", need, "--rounds", 1])
    planner = tandem.Planner.load(state)
    needs = tandem.sim.needs(need_file=need, planner=planner)
    py_msg = py_error(lambda: tandem.sim.run_round(planner, needs, seed=0),
                      tandem.ScheduleError)
    assert_same(cli_msg, py_msg)


def test_every_case_without_a_python_path_says_why() -> None:
    assert all(reason.strip() for reason in NO_PYTHON_PATH.values())
