"""hdw.design against `hdw design` on small cases (a 0.3 s chirp's compliant fit, and a params
file with named unknowns): the same design.json and input as the command for the same
arguments, the limits respected by the returned input, predicted standard errors present and
positive for every free parameter and never larger with more information, the refit check,
and a refused setting as a ValueError naming the option."""

import pytest

import hdw
from hdw_cli import HDW, ROOT, hdw as run_cli, read_json, without

START = ROOT / "data" / "compliant" / "start.toml"
FIT_TOML = (ROOT / "data" / "compliant" / "fit.toml").read_text()


@pytest.fixture(scope="module")
def fit(tmp_path_factory):
    """A compliant fit of a 0.3 s chirp of the seed drive (the docs' worked example, shortened)."""
    d = tmp_path_factory.mktemp("design")
    run_cli("synth", "drive", "--input", "chirp", "--freq", "5", "--t-end", "0.3",
            "--out", d / "chirp.csv")
    config = FIT_TOML.replace('"../../out/compliant/chirp.csv"', '"chirp.csv"').replace(
        '"start.toml"', '"' + START.as_posix() + '"')
    (d / "fit.toml").write_text(config)
    run_cli("fit", "drive", "--config", d / "fit.toml", "--out", d / "fit")
    return d


def record_peak(path):
    import polars as pl

    return pl.read_csv(path)["u"].abs().max()


def assert_same_as_cli(r, cli):
    import polars as pl

    assert without(r.report, {"wall_time_s"}) == without(read_json(cli / "design.json"),
                                                        {"wall_time_s"})
    assert r.input.equals(pl.read_parquet(cli / "input.parquet"))


def assert_ses_positive(r):
    free = r.report["free"]
    assert set(free) <= set(r.parameters["parameter"].to_list())
    for column in ["design_alone_std_error", "design_with_fitted_std_error",
                   "default_chirp_with_fitted_std_error"]:
        ses = dict(zip(r.parameters["parameter"], r.parameters[column]))
        for name in free:
            assert ses[name] is not None and ses[name] > 0, (column, name, ses[name])


def assert_within_limits(r, voltage, duration, rate):
    u, t = r.input["u"], r.input["t"]
    assert 0 < u.abs().max() <= voltage * (1 + 1e-9)
    assert r.input.height == round(duration * rate) + 1
    assert abs(t[1] - t[0] - 1 / rate) < 1e-12 and abs(t[-1] - duration) < 1e-9
    assert r.report["design"]["within"]
    for p in r.report["design"]["peaks"]:
        assert p["peak"] <= p["limit"] * (1 + 1e-9), p


def test_design_from_a_fit_matches_the_cli(fit, tmp_path):
    args = dict(criterion="a", a_params=["Jz", "c"], family=["chirp", "mix"], evaluations=4,
                duration=0.3)
    run_cli("design", "--fit", fit / "fit", "--criterion", "a", "--a-params", "Jz,c",
            "--family", "chirp,mix", "--evaluations", "4", "--duration", "0.3",
            "--out", tmp_path / "cli")
    r = hdw.design(fit / "fit", out=tmp_path / "py", hdw=HDW, **args)
    assert_same_as_cli(r, tmp_path / "cli")
    assert r.out == tmp_path / "py" and (r.out / "report.md").is_file()
    assert r.report["criterion"] == "A-optimal"
    # The defaults of a fit: its record's peak voltage and rate; every freed parameter free.
    fitted = read_json(fit / "fit" / "fit.json")
    freed = {k for k, v in fitted["parameters"].items() if v["free"]}
    if fitted["km_equals_ke"]:
        freed.discard("Km")
    assert set(r.report["free"]) == freed
    voltage = record_peak(fit / "chirp.csv")
    assert r.report["limits"]["voltage_V"] == pytest.approx(voltage, rel=1e-12)
    assert_within_limits(r, voltage, 0.3, 1000.0)
    assert_ses_positive(r)
    # More information never widens a standard error: with the fitted records, the design's
    # SEs are at most those of the records alone and of the design alone.
    for row in r.parameters.iter_rows(named=True):
        if row["parameter"] not in r.report["free"]:
            continue
        with_fitted = row["design_with_fitted_std_error"]
        assert with_fitted <= row["design_alone_std_error"] * (1 + 1e-9), row
        if row["prior_std_error"] is not None:
            assert with_fitted <= row["prior_std_error"] * (1 + 1e-9), row


def test_design_from_params_meets_its_limits(tmp_path):
    r = hdw.design(params=START, free=["R", "Ke", "Jj", "Cj"], duration=0.2, evaluations=8,
                   family=["chirp", "ramp"], voltage=6, speed=3, out=tmp_path / "py", hdw=HDW)
    run_cli("design", "--params", START, "--free", "R,Ke,Jj,Cj", "--duration", "0.2",
            "--evaluations", "8", "--family", "chirp,ramp", "--voltage", "6", "--speed", "3",
            "--out", tmp_path / "cli")
    assert_same_as_cli(r, tmp_path / "cli")
    assert r.report["criterion"] == "D-optimal" and r.report["free"] == ["R", "Ke", "Jj", "Cj"]
    assert r.report["limits"]["speed_rad_s"] == 3
    assert_within_limits(r, 6.0, 0.2, 1000.0)
    assert r.report["design"]["peak_speed_rad_s"] <= 3 * (1 + 1e-9)
    assert_ses_positive(r)


def test_torque_and_travel_limits_reach_the_cli(tmp_path):
    r = hdw.design(params=START, free=["R", "Ke", "Jj", "Cj"], duration=0.2, evaluations=6,
                   family=["chirp", "ramp"], torque=0.5, load_angle=5e-4, out=tmp_path / "py",
                   hdw=HDW)
    run_cli("design", "--params", START, "--free", "R,Ke,Jj,Cj", "--duration", "0.2",
            "--evaluations", "6", "--family", "chirp,ramp", "--torque", "0.5",
            "--load-angle", "5e-4", "--out", tmp_path / "cli")
    assert_same_as_cli(r, tmp_path / "cli")
    assert r.report["limits"]["torque_Nm"] == 0.5
    assert r.report["limits"]["load_angle_rad"] == 5e-4
    assert r.report["design"]["peak_torque_Nm"] <= 0.5 * (1 + 1e-9)
    assert r.report["design"]["peak_load_angle_rad"] <= 5e-4 * (1 + 1e-9)
    assert r.report["design"]["binds"] in ("torque", "load angle")


def test_design_check_refits(tmp_path):
    r = hdw.design(params=START, free=["R", "Ke", "Cj"], duration=0.2, evaluations=4,
                   family=["chirp"], check=2, out=tmp_path / "d", hdw=HDW)
    check = r.report["check"]
    assert check["refits"] == 2 and check["failed"] == []
    for name in ["R", "Ke", "Cj"]:
        row = check["parameters"][name]
        assert row["predicted_std_error"] > 0 and row["spread"] >= 0
        assert 0 <= row["coverage_fit_se"] <= 1
        assert len(row["estimates"]) == len(row["std_errors"]) == len(row["determined"]) == 2
        assert row["determined_in"] == sum(row["determined"])
        assert row["without_std_error_in"] == sum(s is None for s in row["std_errors"])
        if row["without_std_error_in"] < 2:
            assert row["coverage_fit_se"] <= row["coverage_fit_se_given"] <= 1
        if row["determined_in"]:
            assert 0 <= row["coverage_fit_se_determined"] <= 1
    assert len(check["verdicts"]) == 2


def test_a_bad_setting_is_a_value_error(tmp_path):
    with pytest.raises(ValueError, match="--family sine"):
        hdw.design(params=START, free=["R"], family=["sine"], out=tmp_path / "o", hdw=HDW)
    with pytest.raises(ValueError, match="--fit DIR"):
        hdw.design(out=tmp_path / "o", hdw=HDW)


def test_a_closed_loop_design_from_python(tmp_path):
    ctl = ROOT / "data" / "compliant" / "controller.toml"
    r = hdw.design(params=START, free=["R", "Ke", "Jj"], duration=0.2, evaluations=4,
                   family=["chirp"], controller=ctl, reference=0.5, out=tmp_path / "py",
                   hdw=HDW)
    assert r.input.columns == ["t", "reference"]
    assert r.report["controller"]["kp"] == 30.0
    assert 0 < r.input["reference"].abs().max() <= 0.5 * (1 + 1e-9)
    with pytest.raises(ValueError, match="--reference"):
        hdw.design(params=START, free=["R"], reference=0.5, out=tmp_path / "bad", hdw=HDW)
