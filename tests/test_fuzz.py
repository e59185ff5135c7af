"""No input breaks the tool (issue 25): inputs drawn by hypothesis from the shipped files of every
input class (scenario, sweep, vehicle, bushing parameter set, bench programme, rig CSV + META, bench
dataset, MCAP run), mutated in structure (values out of range, of the wrong type, non-finite or in
the wrong unit; keys removed, added, repeated; aliases) and in bytes (undecodable, truncated, cut
or flipped), are each loaded and taken as far as the command's own checks go: vehicles built into
MuJoCo models (not simulated), scenarios scheduled, parameter sets and short bench programmes run,
rig CSVs imported, datasets and recordings read. Every outcome must be a result or an InputError;
anything else, a hang (each case has :data:`CASE_TIMEOUT_S`) or a silent acceptance of what must be
refused (non-finite or beyond 1e300, a repeated key, an alias bomb, undecodable bytes) fails.

The cases are drawn from a fixed seed (reruns try the same cases; ``VSIM_FUZZ_SEED`` draws others)
and their number per class is :data:`EXAMPLES` (1350 in all, README "Hostile input").
"""

from __future__ import annotations

import contextlib
import copy
import functools
import math
import os
import resource
import shutil
import signal
import warnings
from collections import Counter
from pathlib import Path
from typing import Any, Callable, Iterator

import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, given, seed, settings
from hypothesis import strategies as st

from elastokin.bushings.bench.bench_file import load_bench, run_bench
from elastokin.bushings.parameter_sets import load_parameter_set
from elastokin.vehicle.model.builder import build
from elastokin.vehicle.model.elements import BuildOptions
from elastokin.vehicle.model.statics import resolve_preloads
from elastokin.vehicle.model.vehicle_file import load_vehicle
from elastokin.vehicle.scenarios.scenario_file import load_scenario
from elastokin.vehicle.scenarios.schedule import schedule, timestep
from elastokin.core.errors import InputError
from elastokin.core.shipped import BENCH_DIR, DEFAULT_VEHICLE, PARAMETER_SET_DIR, SCENARIO_DIR, SWEEP_DIR
from elastokin.recordings.bench_dataset import read_bench_dataset
from elastokin.recordings.csv_import import import_csv
from elastokin.recordings.run_reader import DamagedRecording, load_run
from elastokin.sweeps.sweep_file import load_sweep
from tests.damage_helpers import chunk_spans

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "data" / "examples" / "kc_import"
BENCH_DATA = ROOT / "data" / "rig" / "bench"
#: Cases drawn per input class.
EXAMPLES = {"scenario": 250, "vehicle": 200, "parameter_set": 150, "bench": 150, "rig_csv": 150,
            "bench_dataset": 150, "mcap": 200, "sweep": 100}
CASE_TIMEOUT_S = 60.0
#: The largest resident memory the worker may reach over the fuzz run [bytes].
MAX_RSS_BYTES = 6 << 30
SEED = int(os.environ.get("VSIM_FUZZ_SEED", "20261124"))

#: Values a careless or hostile file puts where a number, a string, a list or a mapping belongs.
HOSTILE = [0, -1, -1e300, 1e300, 1e9, -1e9, 1e-12, 310, "abc", "", None, True, [], {}, [1, 2, 3], {"a": 1},
           "../../escape", "/tmp/absolute", "x" * 5000, 2 ** 70, [[[[[[1]]]]]], "1e400", "nan", "€"]
NON_FINITE = [math.inf, -math.inf, math.nan, 1e300, -1e300]
#: A YAML alias bomb: nine levels of ten-fold expansion.
BOMB = "".join(f"b{i}: &b{i} [" + ", ".join([f"*b{i - 1}"] * 10) + "]\n" for i in range(1, 10))


class Timeout(Exception):
    """A case ran longer than CASE_TIMEOUT_S: a hang."""


@contextlib.contextmanager
def bounded(seconds: float = CASE_TIMEOUT_S) -> Iterator[None]:
    def expire(signum, frame):
        raise Timeout(f"a case ran longer than {seconds} s")
    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, previous)


def outcome(use: Callable[[], Any]) -> str:
    """``result`` or ``refused`` (InputError); any other exception fails the test with its traceback."""
    with bounded():
        try:
            use()
        except InputError as error:
            assert str(error).strip(), "an error without a message"
            return "refused"
    return "result"


# -- drawing mutations -----------------------------------------------------------------------------
def _paths(node: Any, at: tuple = ()) -> list[tuple]:
    """Every path to a value in a parsed document (the root excluded)."""
    out = []
    items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else ()
    for key, value in items:
        out.append(at + (key,))
        out.extend(_paths(value, at + (key,)))
    return out


def _absurd(value: Any) -> bool:
    """A number no physical key takes: non-finite, or beyond 1e300 in magnitude."""
    return isinstance(value, (int, float)) and not isinstance(value, bool) and not abs(value) < 1e300


def _within(path: tuple, section: tuple) -> bool:
    return len(path) >= len(section) and all(s in ("*", p) for s, p in zip(section, path))


def _get(node: Any, path: tuple) -> Any:
    for key in path:
        node = node[key]
    return node


def _holds_absurd(data: Any, free: tuple[tuple, ...]) -> bool:
    """Whether ``data`` holds an absurd number outside its ``free`` sections."""
    return any(_absurd(_get(data, p)) and not any(_within(p, section) for section in free) for p in _paths(data))


@st.composite
def mutated(draw: st.DrawFn, original: Any, free: tuple[tuple, ...] = ()) -> tuple[str, bool]:
    """YAML text of ``original`` with one to three structural mutations, then maybe a textual one;
    and whether the result must be refused (a non-finite or absurd number where a number stood,
    except in the ``free`` sections, free text for people, ``*`` standing for any list index; a
    repeated key, an alias bomb, undecodable bytes)."""
    data = copy.deepcopy(original)
    for _ in range(draw(st.sampled_from([1, 1, 1, 2, 3]))):
        paths = _paths(data)
        if not paths:
            break
        path = draw(st.sampled_from(paths))
        parent, key = _get(data, path[:-1]), path[-1]
        value = parent[key]
        action = draw(st.sampled_from(["value", "scale", "scale", "delete", "add", "non_finite"]))
        if action == "value":
            parent[key] = copy.deepcopy(draw(st.sampled_from(HOSTILE)))
        elif action == "scale" and isinstance(value, (int, float)) and not isinstance(value, bool):
            parent[key] = value * draw(st.sampled_from([1000.0, 1e-3, -1.0, 1e6, 0.0, 0.5, 2.0, 1.1]))
        elif action == "delete":
            del parent[key]
        elif action == "add" and isinstance(parent, dict):
            parent[draw(st.sampled_from(["unknown_key", "mass_kg", "x"]))] = copy.deepcopy(draw(st.sampled_from(HOSTILE)))
        elif action == "non_finite" and isinstance(value, (int, float)) and not isinstance(value, bool):
            parent[key] = draw(st.sampled_from(NON_FINITE))
    must_refuse = _holds_absurd(data, free)
    text = yaml.safe_dump(data, sort_keys=False, allow_unicode=True, width=200)
    textual = draw(st.sampled_from(["none"] * 6 + ["repeat", "bomb", "bytes", "truncate"]))
    if textual == "repeat" and isinstance(data, dict) and data:
        first = text.splitlines()[0]
        if not first.startswith((" ", "-")):
            text, must_refuse = text + first + "\n", True
    elif textual == "bomb":
        text, must_refuse = text + BOMB, True
    elif textual == "bytes":
        return text + "\udcff", True   # written with surrogateescape: an undecodable byte
    elif textual == "truncate" and text:
        text = text[:draw(st.integers(0, len(text) - 1))]
        try:   # what must be refused may be cut away; what no longer parses needs no verdict
            data = yaml.safe_load(text)
        except yaml.YAMLError:
            return text, False
        must_refuse = _holds_absurd(data, free)
    return text, must_refuse


def write(path: Path, text: str) -> Path:
    path.write_bytes(text.encode("utf-8", "surrogateescape"))
    return path


def check(name: str, result: str, must_refuse: bool, text: str) -> None:
    """Tally ``result``; fail if what must be refused was accepted."""
    TALLY[name][result] += 1
    assert not (must_refuse and result == "result"), f"silently accepted:\n{text[:3000]}"


#: Outcomes of the cases tried, per input class.
TALLY: dict[str, Counter[str]] = {name: Counter() for name in EXAMPLES}


def fuzz(name: str):
    """Hypothesis settings of one input class (its number of cases, the fixed seed, no database);
    the test fails if fewer cases than that were tried."""
    def decorate(test):
        drawn = seed(SEED)(settings(max_examples=EXAMPLES[name], deadline=None, database=None,
                                    suppress_health_check=list(HealthCheck))(test))

        @functools.wraps(drawn)
        def tried(*args: Any, **kwargs: Any) -> None:
            TALLY[name].clear()
            drawn(*args, **kwargs)
            print(f"{name}: {sum(TALLY[name].values())} cases, {dict(TALLY[name])}")
            assert sum(TALLY[name].values()) >= EXAMPLES[name], TALLY[name]
        return tried
    return decorate


def _yaml(path: Path) -> Any:
    return yaml.safe_load(path.read_text())


@pytest.fixture(scope="module", autouse=True)
def memory_stays_bounded() -> Iterator[None]:
    yield
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024 < MAX_RSS_BYTES


@pytest.fixture
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("fuzz")


# -- the input classes -----------------------------------------------------------------------------
SCENARIOS = [p for p in sorted(SCENARIO_DIR.rglob("*.yaml")) if SWEEP_DIR not in p.parents]
SWEEPS = sorted(SWEEP_DIR.glob("*.yaml"))


@fuzz("scenario")
@given(st.sampled_from(SCENARIOS).flatmap(lambda p: mutated({**_yaml(p), "vehicle": str(DEFAULT_VEHICLE)})),
       st.sampled_from([1.0, 1.0, 1.0, 0.05, 1e-9, 1e9, math.inf, math.nan]))
def test_scenarios(folder: Path, case: tuple[str, bool], scale: float) -> None:
    text, must_refuse = case
    path = write(folder / "scenario.yaml", text)
    check("scenario", outcome(lambda: schedule(scenario := load_scenario(path), scale, timestep(scenario))), must_refuse, text)


@fuzz("sweep")
@given(st.sampled_from(SWEEPS).flatmap(lambda p: mutated({**_yaml(p), "vehicle": str(DEFAULT_VEHICLE)})))
def test_sweeps(folder: Path, case: tuple[str, bool]) -> None:
    text, must_refuse = case
    path = write(folder / "sweep.yaml", text)
    check("sweep", outcome(lambda: load_sweep(path).runs), must_refuse, text)


@fuzz("vehicle")
@given(mutated(_yaml(DEFAULT_VEHICLE)))
def test_vehicles(folder: Path, case: tuple[str, bool]) -> None:
    text, must_refuse = case
    path = write(folder / "vehicle.yaml", text)
    check("vehicle", outcome(lambda: build(resolve_preloads(load_vehicle(path)), BuildOptions())), must_refuse, text)


SHORT_BENCH = "model: {model}\nparams: {params}\ndt_s: 0.002\nprogramme: {{type: sine, amplitude_mm: 1.0, frequency_hz: 2, cycles: 2}}\n"


def _runs_finite(bench_path: Path) -> None:
    forces = run_bench(load_bench(bench_path))["F_N"]
    assert np.isfinite(forces).all(), "a bench accepted by the loaders gave a non-finite force"


@fuzz("parameter_set")
@given(st.sampled_from(sorted(PARAMETER_SET_DIR.glob("*.yaml"))).flatmap(
    lambda p: st.tuples(st.just(_yaml(p)["model"]), mutated(_yaml(p)))))
def test_parameter_sets(folder: Path, case: tuple[str, tuple[str, bool]]) -> None:
    model, (text, must_refuse) = case
    path = write(folder / "set.yaml", text)
    bench = write(folder / "bench.yaml", SHORT_BENCH.format(model=model, params=path))

    def use() -> None:
        if load_parameter_set(path).quantity == "translation":
            _runs_finite(bench)
    check("parameter_set", outcome(use), must_refuse, text)


@fuzz("bench")
@given(st.sampled_from(sorted(BENCH_DIR.glob("*.yaml"))).flatmap(lambda p: mutated(_yaml(p))))
def test_bench_programmes(folder: Path, case: tuple[str, bool]) -> None:
    text, must_refuse = case
    path = write(folder / "bench.yaml", text)

    def use() -> None:
        bench = load_bench(path)
        if getattr(bench.programme, "t_s", np.empty(10**6)).size <= 20_000:   # run the short ones
            assert np.isfinite(run_bench(bench)["F_N"]).all()
    check("bench", outcome(use), must_refuse, text)


@st.composite
def mutated_csv(draw: st.DrawFn, text: str) -> tuple[str, bool]:
    """The CSV with one of: a hostile cell, a repeated column, an extra field, a truncation, a
    removed line, undecodable bytes; and whether it must be refused."""
    lines = text.splitlines()
    action = draw(st.sampled_from(["cell", "cell", "repeat_column", "extra_field", "truncate", "drop_line", "bytes"]))
    row = draw(st.integers(1, len(lines) - 1))
    if action == "cell":
        cells = lines[row].split(",")
        value = draw(st.sampled_from(["", "abc", "nan", "inf", "-inf", "1e300", "1e-300", "0", "-1e9", "1,2"]))
        cells[draw(st.integers(0, len(cells) - 1))] = value
        lines[row] = ",".join(cells)
        return "\n".join(lines) + "\n", value in ("abc", "nan", "inf", "-inf", "1e300", "1,2")   # 1,2: an extra field
    if action == "repeat_column":
        cells = lines[0].split(",")
        lines[0] = ",".join(cells[:-1] + [cells[1]])
        return "\n".join(lines) + "\n", True
    if action == "extra_field":
        lines[row] += ",1"
        return "\n".join(lines) + "\n", True
    if action == "truncate":
        cut = "\n".join(lines)
        return cut[:draw(st.integers(0, len(cut)))], False
    if action == "drop_line":
        del lines[row]
        return "\n".join(lines) + "\n", False
    return "\n".join(lines) + "\n\udcff", True


META = {**_yaml(EXAMPLE / "META.yaml"), "scenario": str(SCENARIO_DIR / "pumping.yaml")}
CSV = (EXAMPLE / "kc_pumping.csv").read_text()


@fuzz("rig_csv")
@given(st.one_of(mutated(META).map(lambda m: (m, (CSV, False))), mutated_csv(CSV).map(
    lambda c: ((yaml.safe_dump(META, sort_keys=False), False), c))))
def test_rig_csv_and_meta(folder: Path, case: tuple[tuple[str, bool], tuple[str, bool]]) -> None:
    (meta, meta_refuse), (data, data_refuse) = case
    meta_path, data_path = write(folder / "META.yaml", meta), write(folder / "data.csv", data)
    output = folder / "rig.mcap"
    output.unlink(missing_ok=True)
    check("rig_csv", outcome(lambda: load_run(import_csv(data_path, meta_path, output))), meta_refuse or data_refuse,
          meta + data[:2000])


@pytest.fixture(scope="module")
def bench_dataset(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict, dict[str, str]]:
    """Three records of the shipped bench dataset, each cut to its first 400 samples."""
    manifest = _yaml(BENCH_DATA / "rig.yaml")
    manifest["records"] = manifest["records"][:3]
    csvs = {r["file"]: "\n".join((BENCH_DATA / r["file"]).read_text().splitlines()[:401]) + "\n"
            for r in manifest["records"]}
    return tmp_path_factory.mktemp("bench_dataset"), manifest, csvs


@fuzz("bench_dataset")
@given(st.data())
def test_bench_datasets(bench_dataset: tuple[Path, dict, dict[str, str]], data: st.DataObject) -> None:
    root, manifest, csvs = bench_dataset
    shutil.rmtree(root)
    root.mkdir()
    files = dict(csvs)
    if data.draw(st.booleans()):
        text, must_refuse = data.draw(mutated(manifest, free=(("rig",), ("records", "*", "programme"))))
        write(root / "rig.yaml", text)
    else:
        name = data.draw(st.sampled_from(sorted(files)))
        files[name], must_refuse = data.draw(mutated_csv(files[name]))
        text = yaml.safe_dump(manifest, sort_keys=False)
        write(root / "rig.yaml", text)
    for name, content in files.items():
        write(root / name, content)
    check("bench_dataset", outcome(lambda: read_bench_dataset(root)), must_refuse, text)


@pytest.fixture(scope="module")
def recording(tmp_path_factory: pytest.TempPathFactory) -> bytes:
    """The bytes of the shipped example imported as a rig recording (a small MCAP file)."""
    folder = tmp_path_factory.mktemp("mcap")
    meta = write(folder / "META.yaml", yaml.safe_dump(META, sort_keys=False))
    return import_csv(EXAMPLE / "kc_pumping.csv", meta, folder / "rig.mcap").read_bytes()


def load_run_quietly(recording: bytes, folder: Path):
    """The original recording, read."""
    path = folder / "original.mcap"
    path.write_bytes(recording)
    return load_run(path)


@fuzz("mcap")
@given(st.data())
def test_mcap_runs(recording: bytes, folder: Path, data: st.DataObject) -> None:
    """Truncated, flipped, zeroed, spliced recordings, or with a chunk dropped: an error, or a run
    read as far as it goes with a DamagedRecording warning for each part missing; never a run that
    differs from the original without a word."""
    raw = bytearray(recording)
    action = data.draw(st.sampled_from(["truncate", "flip", "zero", "splice", "drop_chunk", "empty"]))
    at = data.draw(st.integers(0, len(raw) - 1))
    if action == "truncate":
        raw = raw[:at]
    elif action == "flip":
        raw[at] ^= 1 << data.draw(st.integers(0, 7))
    elif action == "zero":
        end = min(len(raw), at + data.draw(st.integers(1, 4096)))
        raw[at:end] = bytes(end - at)
    elif action == "splice":
        raw = raw[:at] + raw[data.draw(st.integers(0, len(raw) - 1)):]
    elif action == "drop_chunk":
        spans = chunk_spans(recording)
        start, end = spans[data.draw(st.integers(0, len(spans) - 1))]
        raw = raw[:start] + raw[end:]
    else:
        raw = bytearray()
    path = folder / "run.mcap"
    path.write_bytes(bytes(raw))
    original = load_run_quietly(recording, folder)

    def use() -> None:
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always")
            run = load_run(path)
        damaged = [w for w in said if issubclass(w.category, DamagedRecording)]
        if action == "truncate" and at < len(recording) - 64:
            assert not run.complete and damaged and "cut" in run.reason, run.reason
        assert all(v.shape == run.t_s.shape for v in run.signals.values())
        assert bool(damaged) == bool(run.damage)
        if not damaged:   # read as a whole file: then it is the original's data
            assert np.array_equal(run.t_s, original.t_s) and run.metadata == original.metadata
            assert all(np.array_equal(run.signals[k], original.signals[k], equal_nan=True) for k in original.signals)
    check("mcap", outcome(use), False, "")
