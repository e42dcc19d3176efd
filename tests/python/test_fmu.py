"""The FMU of `hdw export fmu` in a real importer, FMPy: it validates, and driven through
its inputs it reproduces `hdw simulate` (seed case, a closed loop, a Maxwell-slip drive);
several instances, reset, parameters set after initialisation, and a bad parameter value
that must give an error status, not a crash.

The FMU's binary is the libhd_fmu.so that `cargo test --workspace` (or `cargo build`)
leaves beside target/debug/hdw, where `hdw export fmu` looks for it."""

import ctypes
import math
import pathlib
import shutil
import subprocess

import numpy as np
import pyarrow.parquet as pq
import pytest

fmpy = pytest.importorskip("fmpy")
from fmpy import extract, read_model_description  # noqa: E402
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE  # noqa: E402
from fmpy.fmi3 import FMU3Slave  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

from hdw_cli import HDW, hdw, read_json  # noqa: E402

SEED_T_END = 0.2
STEP = 1e-5  # the communication step of the seed comparison [s]


def export(tmp_path, name, *args):
    out = tmp_path / f"{name}.fmu"
    hdw("export", "fmu", *args, "--out", out)
    return out


def simulate(tmp_path, name, *args):
    """`hdw simulate` with the trace on a 1e-4 s grid: (trace columns, metrics)."""
    out = tmp_path / name
    hdw("simulate", *args, "--dt-out", "1e-4", "--out", out)
    table = pq.read_table(out / "trace.parquet").to_pydict()
    return {k: np.asarray(v, dtype=float) for k, v in table.items()}, read_json(out / "metrics.json")


def seed_signal(t_end=SEED_T_END, step=STEP, mid=False):
    """The seed voltage, 24 V at 50 Hz, sampled every `step` (at the step's start, or its
    middle with `mid`), and no load torque: FMPy's input table."""
    t = np.arange(0.0, t_end + step / 2, step)
    columns = [("time", np.float64), ("u", np.float64), ("T_load", np.float64)]
    signal = np.zeros(len(t), dtype=columns)
    signal["time"] = t
    signal["u"] = 24.0 * np.sin(2 * np.pi * 50.0 * (t + (step / 2 if mid else 0.0)))
    return signal


def run_fmu(fmu, stop_time, step, **kwargs):
    return fmpy.simulate_fmu(
        str(fmu), stop_time=stop_time, output_interval=step, output=["theta_z", "Tb"], **kwargs
    )


def deviation(result, trace):
    """Largest |θz(FMU) − θz(hdw simulate)| on hdw's grid [rad]."""
    fmu_at = np.interp(trace["t"], result["time"], result["theta_z"])
    return float(np.max(np.abs(fmu_at - trace["theta_z"])))


@pytest.mark.parametrize("fmi", ["2", "3"])
def test_fmpy_validation_reports_no_problem(tmp_path, fmi):
    fmu = export(tmp_path, f"drive{fmi}", "--fmi", fmi)
    assert validate_fmu(str(fmu)) == []
    md = read_model_description(str(fmu))
    names = {v.name: v for v in md.modelVariables}
    assert names["u"].causality == "input" and names["u"].unit == "V"
    assert names["theta_z"].causality == "output" and names["theta_z"].unit == "rad"
    assert names["sigma0"].causality == "parameter" and float(names["sigma0"].start) == 1.2e5


def test_seed_case_through_the_voltage_input_matches_hdw_simulate(tmp_path):
    """FMPy holds each input over a step; fed the sine's value at the middle of each
    1e-5 s step, the held voltage has no lag, and the load angle follows `hdw simulate`'s
    continuous sine to second order in the step."""
    trace, metrics = simulate(tmp_path, "seed")
    amp = metrics["metrics"]["thz_amp"]
    fmu = export(tmp_path, "seed")
    result = run_fmu(fmu, SEED_T_END, STEP, input=seed_signal(mid=True))
    assert deviation(result, trace) < 1e-3 * amp


def test_seed_case_with_held_inputs_lags_by_half_a_step(tmp_path):
    """FMI 3, the sine sampled at each step's start: the voltage held over a 1e-5 s step
    lags by half a step on average, so θz lags too, and differs from `hdw simulate` by
    its largest speed times h/2; fed the step's middle value, the difference goes."""
    trace, metrics = simulate(tmp_path, "seed")
    amp = metrics["metrics"]["thz_amp"]
    fmu = export(tmp_path, "seed3", "--fmi", "3")
    held = run_fmu(fmu, SEED_T_END, STEP, input=seed_signal())
    half_step_lag = np.max(np.abs(trace["omega_z"])) * STEP / 2
    assert deviation(held, trace) == pytest.approx(half_step_lag, rel=0.1)
    centred = run_fmu(fmu, SEED_T_END, STEP, input=seed_signal(mid=True))
    assert deviation(centred, trace) < 1e-3 * amp


@pytest.mark.parametrize("fmi", ["2", "3"])
def test_a_fixed_step_fmu_matches_the_adaptive_one(tmp_path, fmi):
    """`--fixed-substeps 2` through FMPy's C calls: each 1e-4 s communication step is two
    fixed Runge–Kutta substeps. Fed the same held sine, its load angle follows the
    adaptive FMU's (rtol 1e-6) to 1e-6 of the amplitude (measured 7.1e-8, FMI 2 and 3),
    and the archive still validates."""
    step = 1e-4
    fixed = export(tmp_path, f"fixed{fmi}", "--fmi", fmi, "--fixed-substeps", "2")
    assert validate_fmu(str(fixed)) == []
    adaptive = export(tmp_path, f"adaptive{fmi}", "--fmi", fmi)
    signal = seed_signal(step=step, mid=True)
    a = run_fmu(adaptive, SEED_T_END, step, input=signal)
    f = run_fmu(fixed, SEED_T_END, step, input=signal)
    amp = float(np.max(np.abs(a["theta_z"])))
    assert np.all(np.isfinite(f["theta_z"]))
    assert float(np.max(np.abs(f["theta_z"] - a["theta_z"]))) < 1e-6 * amp


def test_a_fixed_step_is_refused_for_a_drive_it_cannot_integrate(tmp_path):
    """A motor with inductance is not among what the fixed step integrates: the export
    names the option and the setting, and writes nothing."""
    out = tmp_path / "l.fmu"
    r = subprocess.run([HDW, "export", "fmu", "--set", "L=1e-3", "--fixed-substeps", "4",
                        "--out", str(out)], capture_output=True, text=True)
    assert r.returncode != 0
    assert "--fixed-substeps 4" in r.stderr and "L = 1e-3" in r.stderr, r.stderr
    assert not out.exists()


def test_python_export_fmu_writes_a_fixed_step_fmu_and_refuses_a_bad_count(tmp_path):
    """`hdw.export_fmu(fixed_substeps=4)` writes the FMU table the binary reads; a count
    that is not a whole number >= 1 is refused before hdw runs."""
    import zipfile

    package = pytest.importorskip("hdw")
    out = package.export_fmu(tmp_path / "f.fmu", fixed_substeps=4, hdw=HDW)
    text = zipfile.ZipFile(out).read("resources/model.toml").decode()
    assert "[fmu]\nfixed_substeps = 4" in text
    for bad in (0, 2.5, True):
        with pytest.raises(ValueError, match="fixed_substeps"):
            package.export_fmu(tmp_path / "g.fmu", fixed_substeps=bad, hdw=HDW)


def test_closed_loop_fmu_matches_hdw_simulate(tmp_path):
    """A sampled PID with friction compensation (its step reference runs inside the FMU),
    a constant load torque through T_load."""
    params = tmp_path / "pid.toml"
    params.write_text(
        "[controller]\nkp = 2000.0\nki = 20000.0\nperiod = 1e-3\ncompensation = \"friction\"\n"
        "[controller.reference]\nkind = \"step\"\namplitude = 1e-3\n"
    )
    trace, _ = simulate(tmp_path, "pid", "--params", params, "--t-end", "0.3", "--load-torque", "2")
    fmu = export(tmp_path, "pid", "--params", params)
    md = read_model_description(str(fmu))
    assert [v.name for v in md.modelVariables if v.causality == "input"] == ["T_load"]
    result = run_fmu(fmu, 0.3, 1e-4, start_values={}, input=load_signal(0.3, 2.0))
    assert deviation(result, trace) < 1e-3 * 1e-3


def load_signal(t_end, torque):
    t = np.array([0.0, t_end])
    s = np.zeros(2, dtype=[("time", np.float64), ("T_load", np.float64)])
    s["time"], s["T_load"] = t, torque
    return s


def test_maxwell_slip_drive_matches_hdw_simulate(tmp_path):
    trace, metrics = simulate(tmp_path, "slip", "--stiffness", "maxwell-slip", "--set", "ms_n=10")
    amp = metrics["metrics"]["thz_amp"]
    fmu = export(tmp_path, "slip", "--stiffness", "maxwell-slip", "--set", "ms_n=10")
    result = run_fmu(fmu, SEED_T_END, STEP, input=seed_signal(mid=True))
    assert deviation(result, trace) < 1e-3 * amp


class Slave:
    """An FMI 2 instance driven by hand, with its log messages collected."""

    def __init__(self, unzipdir, md, name):
        self.messages = []
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.fmu = FMU2Slave(
            guid=md.guid,
            unzipDirectory=unzipdir,
            modelIdentifier=md.coSimulation.modelIdentifier,
            instanceName=name,
        )
        callbacks = fmi2CallbackFunctions()
        callbacks.logger = fmi2CallbackLoggerTYPE(self._log)
        self._callbacks = callbacks
        from fmpy.logging import addLoggerProxy

        addLoggerProxy(ctypes.byref(callbacks))
        self.fmu.instantiate(callbacks=callbacks)

    def _log(self, env, name, status, category, message):
        self.messages.append(message.decode())

    def start(self, **params):
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()
        for k, v in params.items():
            self.fmu.setReal([self.vr[k]], [v])

    def run(self, volts, n, h=1e-4):
        """n steps of h with u held at `volts`; θz after each."""
        out = []
        for k in range(n):
            self.fmu.setReal([self.vr["u"]], [volts])
            self.fmu.doStep(k * h, h)
            out.append(self.fmu.getReal([self.vr["theta_z"]])[0])
        return out


@pytest.fixture
def unzipped(tmp_path):
    fmu = export(tmp_path, "drive")
    d = extract(str(fmu))
    yield d, read_model_description(d)
    shutil.rmtree(d, ignore_errors=True)


def test_several_instances_keep_their_own_state(unzipped):
    d, md = unzipped
    alone = Slave(d, md, "alone")
    alone.start()
    a_ref = alone.run(24.0, 200)
    alone.fmu.terminate()
    alone.fmu.freeInstance()
    a, b = Slave(d, md, "a"), Slave(d, md, "b")
    a.start()
    b.start(c=3e4)
    a_run, b_run = [], []
    for k in range(200):  # interleaved, step by step
        a.fmu.setReal([a.vr["u"]], [24.0])
        b.fmu.setReal([b.vr["u"]], [-12.0])
        a.fmu.doStep(k * 1e-4, 1e-4)
        b.fmu.doStep(k * 1e-4, 1e-4)
        a_run.append(a.fmu.getReal([a.vr["theta_z"]])[0])
        b_run.append(b.fmu.getReal([b.vr["theta_z"]])[0])
    assert a_run == a_ref
    assert b_run[-1] < 0 < a_run[-1]
    assert b.fmu.getReal([b.vr["c"]])[0] == 3e4


def test_reset_runs_the_same_again_and_parameters_set_after_initialisation_count(unzipped):
    d, md = unzipped
    s = Slave(d, md, "s")
    s.start()
    first = s.run(24.0, 150)
    s.fmu.reset()
    s.start()
    assert s.run(24.0, 150) == first
    s.fmu.reset()
    s.start(Jz=4.8e-2)  # after initialisation, before the first step
    heavier = s.run(24.0, 150)
    # A constant voltage from rest: twice the load inertia, a slower start.
    assert 0 < heavier[-1] < first[-1]


def test_a_bad_parameter_value_is_an_error_status_with_its_name(unzipped):
    d, md = unzipped
    s = Slave(d, md, "bad")
    s.fmu.setupExperiment(startTime=0.0)
    s.fmu.enterInitializationMode()
    with pytest.raises(Exception) as err:
        s.fmu.setReal([s.vr["sigma0"]], [-1.0])
    assert "fmi2SetReal" in str(err.value) and "3" in str(err.value)  # fmi2Error
    assert any("sigma0" in m and "-1" in m for m in s.messages), s.messages
    # The instance still works with the value it had.
    s.fmu.exitInitializationMode()
    assert s.fmu.getReal([s.vr["sigma0"]])[0] == 1.2e5
    s.fmu.doStep(0.0, 1e-4)


def test_fmi3_instances_step_and_reset(tmp_path):
    fmu = export(tmp_path, "drive3", "--fmi", "3")
    d = extract(str(fmu))
    md = read_model_description(d)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    s = FMU3Slave(
        guid=md.guid, unzipDirectory=d, modelIdentifier=md.coSimulation.modelIdentifier
    )
    s.instantiate()
    runs = []
    for _ in range(2):
        s.enterInitializationMode(startTime=0.0)
        s.exitInitializationMode()
        out = []
        for k in range(100):
            s.setFloat64([vr["u"]], [24.0])
            s.doStep(k * 1e-4, 1e-4)
            out.append(s.getFloat64([vr["theta_z"], vr["time"]]))
        runs.append(out)
        s.reset()
    assert runs[0] == runs[1]
    assert runs[0][-1][1] == pytest.approx(1e-2)
    s.freeInstance()
    shutil.rmtree(d, ignore_errors=True)


def test_python_export_fmu_writes_the_params_it_is_given(tmp_path):
    hdw_pkg = pytest.importorskip("hdw")
    from hdw_cli import HDW

    out = hdw_pkg.export_fmu(
        tmp_path / "py.fmu", params={"c": 6e4}, stiffness="maxwell-slip", fmi=3, hdw=HDW
    )
    md = read_model_description(str(out))
    assert md.fmiVersion == "3.0"
    start = {v.name: v.start for v in md.modelVariables}
    assert float(start["c"]) == 6e4
    assert "maxwell-slip" in md.description
    with pytest.raises(ValueError, match="sigma0"):
        hdw_pkg.export_fmu(tmp_path / "bad.fmu", params={"sigma0": -1.0}, hdw=HDW)


def test_the_fmpy_example_of_docs_fmu_runs(tmp_path):
    """The ```python block of docs/fmu.md, run where the block before it wrote out/drive.fmu."""
    doc = (pathlib.Path(__file__).resolve().parents[2] / "docs" / "fmu.md").read_text()
    code = doc.split("```python\n", 1)[1].split("```", 1)[0]
    (tmp_path / "out").mkdir()
    hdw("export", "fmu", "--out", "out/drive.fmu", cwd=tmp_path)
    import os

    here = os.getcwd()
    os.chdir(tmp_path)
    try:
        exec(compile(code, "docs/fmu.md", "exec"), {})
    finally:
        os.chdir(here)
