"""``tandem.Console``: the operator's console fed by a Python control loop. The server runs on
a free port; the test reads its newest frame (``/frame``) and its event stream (``/events``)
and checks them against the coordinator the loop ticks: the page's low-confidence robot is the
coordinator's, its countdown the coordinator's pre-alert, a control comes back confirmed and
pauses the loop."""

from __future__ import annotations

import json
import socket
import time
import urllib.error
import urllib.request

import pytest

import tandem


def get_json(url: str):
    with urllib.request.urlopen(url, timeout=5) as r:
        return json.loads(r.read())


def post(url: str, body: dict):
    req = urllib.request.Request(
        url + "control",
        data=json.dumps(body).encode(),
        headers={"Content-Type": "application/json"},
    )
    try:
        with urllib.request.urlopen(req, timeout=5) as r:
            return r.status, json.loads(r.read())
    except urllib.error.HTTPError as e:
        return e.code, json.loads(e.read())


def serve_until(console, coord, tick, want, what: str, timeout_s: float = 10.0):
    """Publishes ``tick`` of ``coord`` (not ticking) until the console's newest frame
    satisfies ``want``; returns that frame."""
    t0 = time.monotonic()
    frame = None
    while time.monotonic() - t0 < timeout_s:
        console.apply(coord)
        console.publish(tick, coord)
        try:
            frame = get_json(console.url + "frame")
        except urllib.error.HTTPError as e:
            assert e.code == 503  # before the first snapshot
            frame = None
        if frame is not None and want(frame):
            return frame
        time.sleep(0.01)
    raise AssertionError(f"timed out waiting for {what}: {frame}")


def test_the_page_shows_the_coordinators_lc_robot_and_pre_alert(overlapping_planner) -> None:
    coord = overlapping_planner.controller()
    with tandem.Console(coord, port=0) as console:
        assert console.url == f"http://127.0.0.1:{console.port}/"
        assert console.port > 0 and console.running
        assert "Console(" in repr(console)
        # Tick until a robot is low-confidence, publishing each tick.
        ticks = 0
        tick = coord.tick()
        ticks += 1
        console.publish(tick, coord)
        while not coord.low_conf_now.any() and not coord.is_finished:
            assert console.apply(coord)
            tick = coord.tick()
            ticks += 1
            console.publish(tick, coord)
        assert console.published == ticks
        assert coord.low_conf_now.any(), "the overlapping schedule has a low-confidence stretch"
        lc = int(coord.low_conf_now.argmax()) + 1
        frame = serve_until(console, coord, tick, lambda f: f["tick"] == ticks, f"tick {ticks}")
        states = {r["robot"]: r["state"] for r in frame["robots"]}
        assert [k for k, s in states.items() if s == "lc"] == [lc]
        assert frame["attention"]["robot"] == lc
        assert frame["attention"]["left_s"] > 0
        # The countdown is the coordinator's pre-alert of this tick, exactly.
        pre = tick.next
        if pre is None:
            assert frame["next"] is None
        else:
            assert frame["next"]["robot"] == pre["robot"] + 1
            assert frame["next"]["in_s"] == pre["earliest_s"]
            latest = frame["next"]["latest_s"]
            assert (latest is None) == (pre["latest_s"] == float("inf"))
            assert frame["prealert"] == (pre["earliest_s"] <= frame["lead_s"])
        assert frame["lead_s"] == 7.0
        assert frame["health"]["published"] >= ticks
        # Not reported yet: no count on the strip.
        assert all(r["strip"]["corrections"] is None for r in frame["robots"])
        # Two corrected ticks in a row on the lc robot are one correction; others none.
        for _ in range(2):
            assert coord.low_conf_now.any()
            tick = coord.tick()
            ticks += 1
            console.publish(tick, coord, corrected=True)
        frame = serve_until(console, coord, tick, lambda f: f["tick"] == ticks, f"tick {ticks}")
        counts = {r["robot"]: r["strip"]["corrections"] for r in frame["robots"]}
        assert counts == {k: (1 if k == lc else 0) for k in counts}, counts

        # The event stream carries the same frames.
        with urllib.request.urlopen(console.url + "events", timeout=5) as stream:
            for raw in stream:
                line = raw.decode().strip()
                if line.startswith("data:"):
                    streamed = json.loads(line[len("data:") :])
                    break
        assert streamed["tick"] == ticks
        assert [r["robot"] for r in streamed["robots"] if r["state"] == "lc"] == [lc]

        # A control: claim, pause; the loop applies it at its next boundary and confirms it.
        assert post(console.url, {"client": "py", "id": 1, "op": "claim"})[0] == 200
        status, answer = post(console.url, {"client": "py", "id": 2, "op": "pause"})
        assert (status, answer["pending"]) == (202, True)
        frame = serve_until(
            console,
            coord,
            tick,
            lambda f: any(a["id"] == 2 and a["ok"] for a in f["acks"]) and f["paused"],
            "the pause's confirmation",
        )
        assert console.paused and not console.apply(coord)
        # A malformed control is refused with the reason; the loop never sees it.
        status, answer = post(console.url, {"client": "py", "id": 3, "op": "explode"})
        assert status == 400 and "explode" in answer["error"]
        assert console.paused
    assert not console.running
    console.close()  # idempotent


def test_a_continuous_cell_and_bad_input(overlapping_planner) -> None:
    coord = overlapping_planner.controller(cell="continuous")
    rounds = overlapping_planner.controller()
    console = tandem.Console(coord, lead_s=12.5, max_hz=60)
    try:
        tick = coord.tick()
        console.publish(tick, coord)
        frame = serve_until(console, coord, tick, lambda f: f["tick"] == 1, "the first tick")
        assert frame["cell"] == "continuous" and frame["lead_s"] == 12.5
        assert len(frame["robots"]) == coord.n_robots
        # A coordinator or tick of another kind is a clear error, the console unaffected.
        with pytest.raises(tandem.InputError, match="continuous cell"):
            console.publish(rounds.tick(), rounds)
        with pytest.raises(tandem.InputError, match="controller"):
            console.apply("not a coordinator")
        with pytest.raises(tandem.InputError, match="tick"):
            console.publish(42, coord)
        console.publish(coord.tick(), coord)
    finally:
        console.close()
    # Bad settings: named, never a panic.
    with pytest.raises(tandem.InputError, match="controller"):
        tandem.Console(object())
    with pytest.raises(tandem.InputError, match="host"):
        tandem.Console(rounds, host="localhost:80")
    with pytest.raises(tandem.ParamError, match="max_hz"):
        tandem.Console(rounds, max_hz=0)
    with pytest.raises(tandem.ParamError, match="lead_s"):
        tandem.Console(rounds, lead_s=float("nan"))
    # A taken port: the error says so and how to pick a free one.
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        with pytest.raises(tandem.ParamError, match="port 0"):
            tandem.Console(rounds, port=s.getsockname()[1])


def test_the_guides_python_loop_runs(overlapping_planner, tmp_path, monkeypatch, capsys) -> None:
    """docs/guide.md, "The operator's screen": the Python loop runs as printed on a saved
    state (without the real-time sleep: a whole round at full speed)."""
    from pathlib import Path

    text = (Path(__file__).resolve().parents[2] / "docs" / "guide.md").read_text()
    start = text.index("### The operator's screen")
    section = text[start : text.index("\n## ", start)]
    (code,) = [b.split("```")[0] for b in section.split("```python\n")[1:]]
    overlapping_planner.save(tmp_path / "cell.tandem")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(time, "sleep", lambda s: None)
    scope: dict = {}
    exec(compile(code, "guide.md", "exec"), scope)
    assert scope["coord"].is_finished
    assert scope["console"].published > 0 and not scope["console"].running
    assert capsys.readouterr().out.startswith("http://127.0.0.1:")
