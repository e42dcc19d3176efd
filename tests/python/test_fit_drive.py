"""hdw.fit_drive against `hdw fit drive` on the shipped EMPS estimation run: the same fit.json
(only the wall times differ), the values of the best law, the outputs written where asked,
and a refused configuration as a ValueError naming the file and the field."""

import pytest

import hdw
from hdw_cli import HDW, ROOT, hdw as run_cli, read_json, without

VARYING = {"seconds", "config"}


def config(tmp_path, friction="coulomb-viscous"):
    """The shipped EMPS configuration with one friction law, its record by absolute path."""
    text = (ROOT / "data" / "emps" / "fit.toml").read_text()
    data = ROOT / "data" / "emps" / "DATA_EMPS.mat"
    text = text.replace('friction = "all"', f'friction = "{friction}"')
    text = text.replace('file = "DATA_EMPS.mat"', f'file = "{data.as_posix()}"')
    path = tmp_path / "fit.toml"
    path.write_text(text)
    return path


def test_fit_drive_matches_the_cli(tmp_path):
    cfg = config(tmp_path)
    run_cli("fit", "drive", "--config", cfg, "--out", tmp_path / "cli")
    fit = hdw.fit_drive(cfg, hdw=HDW)
    expected = read_json(tmp_path / "cli" / "fit.json")
    assert without(fit.report, VARYING) == without(expected, VARYING)
    assert fit.best == "coulomb-viscous" and fit.out is None
    assert set(fit.values) == {"M", "Fv", "Fc", "offset", "gain"}
    # The published IDIM-LS mass is 95.11 kg; the output-error fit stays close to it.
    assert abs(fit.values["M"] - 95.11) < 1.0
    est = fit.scores()["estimation"]
    assert 0.0 < est["force"]["rel_error"] < 10.0
    assert "Controller check" in fit.summary


def test_fit_drive_writes_where_asked(tmp_path):
    cfg = config(tmp_path, "directional")
    out = tmp_path / "out"
    fit = hdw.fit_drive(cfg, out=out, hdw=HDW)
    assert fit.out == out
    for f in ["fit.json", "params.toml", "report.md", "force.svg"]:
        assert (out / f).is_file(), f
    assert fit.laws["directional"] == fit.values


def test_bad_configuration_is_a_value_error(tmp_path):
    cfg = config(tmp_path)
    cfg.write_text(cfg.read_text().replace('position = "qm"', 'position = "qx"'))
    with pytest.raises(ValueError, match="missing variable 'qx'"):
        hdw.fit_drive(cfg, hdw=HDW)


def fitted_both_ways(cfg, tmp_path):
    """Fit `cfg` with the command and with hdw.fit_drive: the same fit.json but for the
    wall time; returns the Python fit, whose motor resistance must be back at the seed's 6 Ω
    and whose Km must follow Ke."""
    run_cli("fit", "drive", "--config", cfg, "--out", tmp_path / "cli")
    fit = hdw.fit_drive(cfg, hdw=HDW)
    expected = read_json(tmp_path / "cli" / "fit.json")
    assert without(fit.report, VARYING | {"wall_time_s"}) == without(expected, VARYING | {"wall_time_s"})
    assert abs(fit.values["R"] - 6.0) < 0.05 and fit.values["Km"] == fit.values["Ke"]
    return fit


def test_fit_drive_takes_a_compliant_configuration(tmp_path):
    """A voltage test of the simulator's drive fitted back through hdw.fit_drive: the same
    fit.json as the command, the values and scores of the one model."""
    rec = tmp_path / "chirp.csv"
    run_cli("synth", "drive", "--freq", "5", "--t-end", "1", "--out", rec)
    cfg = tmp_path / "fit.toml"
    cfg.write_text(
        'transmission = "compliant"\nvoltage_between = "hold"\n'
        '[params]\nR = 7.0\nKe = 0.45\n'
        '[[experiment]]\nname = "chirp"\nfile = "chirp.csv"\ntime = "t"\nvoltage = "u"\n'
        'motor = "theta_m"\nload = "theta_l"\ncurrent = "i"\n'
        '[fit]\nfree = ["R", "Ke", "Jj", "Cj"]\n'
    )
    fit = fitted_both_ways(cfg, tmp_path)
    assert fit.best == "compliant" and fit.laws["compliant"] == fit.values
    assert fit.scores()["chirp"]["current"]["rmse_over_noise"] < 1.2


def test_fit_drive_takes_a_closed_loop_compliant_configuration(tmp_path):
    """A record of the simulator's drive in its position loop fitted back through
    hdw.fit_drive: the same fit.json as the command, the controller check in the report and
    the command compared as an output."""
    rec = tmp_path / "loop.csv"
    run_cli("synth", "drive", "--loop-kp", "30", "--loop-kv", "0.5", "--freq", "5",
            "--t-end", "0.5", "--motor-counts", "65536", "--out", rec)
    cfg = tmp_path / "fit.toml"
    cfg.write_text(
        'transmission = "compliant"\n'
        '[params]\nR = 7.0\nKe = 0.45\n'
        '[[experiment]]\nname = "steps"\nfile = "loop.csv"\ntime = "t"\nreference = "ref"\n'
        'command = "cmd"\nmotor = "theta_m"\nload = "theta_l"\ncurrent = "i"\n'
        '[controller]\nkp = 30.0\nkv = 0.5\n'
        '[fit]\nfree = ["R", "Ke", "Jj", "Cj"]\n'
    )
    fit = fitted_both_ways(cfg, tmp_path)
    assert fit.report["controller"]["delay"] == 0 and fit.report["controller"]["feedback"] == "motor"
    assert fit.scores()["steps"]["command"]["rmse_over_noise"] < 1.2
