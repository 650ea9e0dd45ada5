"""Property-based tests (hypothesis): whatever a user types or whatever a disk leaves behind, cerebx
answers with one ``where: problem`` line per problem and exit code 2, never a traceback.

``make test`` runs a fixed, derandomized set of examples (well under a minute); ``make test-full`` runs
the ``slow`` variants with many more."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cerebx.cli import main
from cerebx.guard import conf_roots

pytestmark = pytest.mark.integration

FAST = settings(max_examples=40, derandomize=True, deadline=None, database=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
FULL = settings(FAST, max_examples=400, derandomize=False)
FAST_FILES = settings(FAST, max_examples=40)
FAST_STATES = settings(FAST, max_examples=15)
FULL_FILES = settings(FULL, max_examples=600)

PROBLEM = re.compile(r"^\S[^\n]*?: \S")  # "where: problem"

GROUPS: dict[str, list[str]] = {}
for _root in conf_roots():  # cerebx's groups and every installed plugin's
    for _d in sorted(_root.iterdir()):
        if _d.is_dir() and _d.name != "__pycache__":
            GROUPS[_d.name] = sorted({*GROUPS.get(_d.name, []), *(p.stem for p in _d.glob("*.yaml"))})
TOP_KEYS = ["seed", "trials", "init_from", "start_at", "warmup_trials", "events", "name", "control_dt_ms",
            "recording.decimation", "recording.chunk_size_kb", "recording.compression", "recording.progress",
            "recording.save_state", "recording.joint_states", "controller.kp", "controller.mf.fibers_per_signal",
            "controller.pathway_delay_ms", "controller.record_spikes", "plant.physics_dt_ms",
            "plant.torque_limit_Nm", "delay.total_ms", "task.period_s", "controller.network.dt_ms",
            "controller.network.populations.gc.size",
            "controller.network.projections.pf_pc.plasticity.kernel_peak_ms", "robot", "brain",
            "spinal", "muscle", "nonexistent", "controller.nonexistent.deep", "hydra.run.dir", "_target_",
            "hydra.callbacks.x._target_"]

values = st.one_of(
    st.integers(-10**13, 10**13).map(str),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.sampled_from(["null", "true", "false", "[]", "{}", "[1,2]", "{a:1}", "''", "'a b'", "${seed}", "${nope}",
                     "1e12", "-0", "nan", "inf", "[1,[2,[3]]]", "{kind:pd}", "/nonexistent", "runs", "x,y",
                     "range(1,3)", "choice(1,2)", "[{kind:x}]", "[{kind:hold}]", "{kind:x}", "\\", "'", "\"", "=",
                     "???", "${oc.env:HOME}"]),
    st.text(alphabet=st.characters(blacklist_categories=("Cs",)), max_size=12),
)
group_override = st.sampled_from(sorted(GROUPS)).flatmap(
    lambda g: st.tuples(st.sampled_from(["", "+", "~", "++"]), st.just(g),
                        st.one_of(st.sampled_from(GROUPS[g] or ["none"]), st.text(max_size=8))))
key_override = st.tuples(st.sampled_from(["", "+", "~", "++"]), st.sampled_from(TOP_KEYS), values)
override = st.one_of(group_override, key_override).map(
    lambda t: f"{t[0]}{t[1]}" if t[0] == "~" and not t[2] else f"{t[0]}{t[1]}={t[2]}")
override_sets = st.lists(override, max_size=5).map(lambda xs: ["+task=circle", *xs])


def _assert_honest(code: int, out: str, err: str) -> None:
    assert "Traceback" not in out + err, err
    if code == 0:
        assert "# valid:" in out
        return
    assert code == 2, (code, err)
    lines = [ln for ln in err.strip().splitlines() if ln]
    assert lines, "refused without saying why"
    assert all(PROBLEM.match(ln) for ln in lines), lines


def _check_overrides(overrides: list[str], capsys) -> None:
    code = main(["validate", *overrides])
    out, err = capsys.readouterr()
    _assert_honest(code, out, err)


@FAST
@given(override_sets)
def test_random_overrides_validate_or_are_refused_in_one_line_each(capsys, overrides):
    _check_overrides(overrides, capsys)


@pytest.mark.slow
@FULL
@given(override_sets)
def test_random_overrides_many(capsys, overrides):
    _check_overrides(overrides, capsys)


# ---- damaged files ----------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def good_run(tmp_path_factory):
    """A demo run and a small-SNN run with its learned state, written once."""
    from cerebx.config import load
    from cerebx.loop.runner import run_experiment

    root = tmp_path_factory.mktemp("good")
    run_experiment(load(["+experiment=demo", "trials=1"])[0], root / "demo")
    run_experiment(load(["+task=circle", "+experiment=small_snn", "trials=1"])[0], root / "snn")
    return root


def _mutate(data: bytes, how: str, at: float, junk: bytes) -> bytes:
    i = int(at * len(data))
    if how == "truncate":
        return data[:i]
    if how == "flip":
        return data[:i] + bytes(b ^ 0x5A for b in data[i: i + max(1, len(junk))]) + data[i + max(1, len(junk)):]
    if how == "insert":
        return data[:i] + junk + data[i:]
    return junk  # replace


damage = st.tuples(st.sampled_from(["truncate", "flip", "insert", "replace"]), st.floats(0, 1),
                   st.binary(max_size=64))

json_values = st.recursive(st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False) | st.text(max_size=8),
                           lambda c: st.lists(c, max_size=3) | st.dictionaries(st.text(max_size=8), c, max_size=3),
                           max_leaves=8)
summary_change = st.one_of(
    st.tuples(st.just("set"), st.sampled_from(["status", "task", "controller", "plant", "delay", "seed", "trials",
                                               "trials_completed", "mae_per_trial", "final_mae", "sim_seconds",
                                               "wall_seconds", "rt_factor", "presets", "error", "pid", "network"]),
              json_values),
    st.tuples(st.just("drop"), st.sampled_from(["status", "task", "seed", "trials", "plant", "delay"]), st.none()),
    st.tuples(st.just("whole"), st.just(""), json_values),
)


def _fresh(tmp: Path, good: Path) -> Path:
    d = tmp / "run"
    if d.exists():
        shutil.rmtree(d)
    shutil.copytree(good, d)
    return d


def _damaged_run(tmp: Path, good_run: Path, target: str, dmg, change) -> Path:
    d = _fresh(tmp, good_run / "demo")
    if target == "run.mcap":
        (d / "run.mcap").write_bytes(_mutate((d / "run.mcap").read_bytes(), *dmg))
    elif target == "summary.json":
        s = json.loads((d / "summary.json").read_text())
        kind, key, value = change
        if kind == "set":
            s[key] = value
        elif kind == "drop":
            s.pop(key, None)
        else:
            s = value
        (d / "summary.json").write_text(json.dumps(s))
    else:
        (d / "summary.json").write_bytes(_mutate((d / "summary.json").read_bytes(), *dmg))
    return d


def _check_files(tmp: Path, good_run: Path, target: str, dmg, change, capsys, with_report: bool) -> None:
    d = _damaged_run(tmp, good_run, target, dmg, change)
    code = main(["inspect", str(d)])
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    assert code in (0, 2) and (code == 0 or len(err.strip().splitlines()) == 1), (code, err)
    if code == 2:
        assert PROBLEM.match(err.strip()), err
    if with_report:
        code = main(["report", str(d), "--out", str(tmp / "rep"), "--figures", "fig3_4"])
        out, err = capsys.readouterr()
        assert code == 0 and "Traceback" not in out + err, err
        assert (tmp / "rep" / "index.html").exists()
        assert all(PROBLEM.match(ln) for ln in err.strip().splitlines() if ln), err


targets = st.sampled_from(["run.mcap", "summary.json", "summary.bytes"])


@FAST_FILES
@given(targets, damage, summary_change, st.integers(0, 5))
def test_damaged_logs_and_summaries_are_one_line(good_run, tmp_path, capsys, target, dmg, change, n):
    _check_files(tmp_path, good_run, target, dmg, change, capsys, with_report=n == 0)


@pytest.mark.slow
@FULL_FILES
@given(targets, damage, summary_change, st.integers(0, 5))
def test_damaged_logs_and_summaries_many(good_run, tmp_path, capsys, target, dmg, change, n):
    _check_files(tmp_path, good_run, target, dmg, change, capsys, with_report=n == 0)


def _check_state(tmp: Path, good_run: Path, dmg, capsys) -> None:
    d = tmp / "state"
    d.mkdir(exist_ok=True)
    data = (good_run / "snn" / "controller_state.npz").read_bytes()
    (d / "controller_state.npz").write_bytes(_mutate(data, *dmg))
    code = main(["validate", "+task=circle", "+experiment=small_snn", f"init_from={d}"])
    out, err = capsys.readouterr()
    _assert_honest(code, out, err)
    if code == 2:
        assert len(err.strip().splitlines()) == 1 and err.startswith("init_from: "), err


@FAST_STATES
@given(damage)
def test_damaged_states_are_one_line_at_validation(good_run, tmp_path, capsys, dmg):
    _check_state(tmp_path, good_run, dmg, capsys)


@pytest.mark.slow
@FULL
@given(damage)
def test_damaged_states_many(good_run, tmp_path, capsys, dmg):
    _check_state(tmp_path, good_run, dmg, capsys)
