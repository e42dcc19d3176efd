"""hdw.simulate_many: each row is the run hdw.simulate gives for that parameter set (to
the last digit, in order, whatever the thread count); a bad point fails its own row with
its error, like a sweep, and the other rows are unaffected."""

import math

import numpy as np
import polars as pl
import pytest

import hdw

SHORT = dict(t_end=0.04, cycles=1)


def test_rows_equal_single_runs_and_a_failing_run_is_a_row():
    sets = [{"c": 4.0e4}, {"c": -1.0}, {"sigma0": 2.0e5, "Tc": 0.2}, {"Tc": float("nan")}]
    df = hdw.simulate_many(sets, **SHORT)
    assert df["run_index"].to_list() == [0, 1, 2, 3]
    assert df["status"].to_list() == ["ok", "failed", "ok", "failed"]
    assert df["error"][0] is None and df["error"][2] is None
    assert "parameter 'c' = -1" in df["error"][1] and "> 0" in df["error"][1]
    assert "parameter 'Tc'" in df["error"][3]
    assert df["thz_amp"][1] is None and df["steps"][1] == 0
    assert df["c"][1] == -1.0  # the row records the point it was given
    for k in (0, 2):
        single = hdw.simulate(sets[k], trace=False, **SHORT)
        for name in hdw.metrics():
            v = df[name][k]
            assert (v is None and math.isnan(single.metrics[name])) or v == single.metrics[name], name
        assert df["steps"][k] == single.solver["steps"]


def test_a_solver_failure_inside_a_batch_is_a_failed_row():
    # 10 ms of the seed case take 167 steps, with a light motor 708: a budget of 400
    # lets the first run finish and stops the second.
    df = hdw.simulate_many([{"Jj": 6.8e-4}, {"Jj": 1e-6}], t_end=0.01, max_steps=400)
    assert df["status"].to_list() == ["ok", "failed"]
    assert "more than 400 steps" in df["error"][1]


def test_array_and_dataframe_forms_equal_the_dict_form():
    rng = np.random.default_rng(7)
    x = np.column_stack([rng.uniform(4e4, 6e4, 12), rng.uniform(200, 400, 12)])
    by_array = hdw.simulate_many(x, names=["c", "B"], metrics=["thz_amp", "efficiency"], **SHORT)
    by_dicts = hdw.simulate_many([{"c": a, "mem_B": b} for a, b in x],
                                 metrics=["thz_amp", "efficiency"], **SHORT)
    by_frame = hdw.simulate_many(pl.DataFrame({"c": x[:, 0], "B": x[:, 1]}),
                                 metrics=["thz_amp", "efficiency"], **SHORT)
    keep = ["run_index", "c", "mem_B", "thz_amp", "efficiency", "steps"]
    assert by_array.select(keep).equals(by_dicts.select(keep))
    assert by_array.select(keep).equals(by_frame.select(keep))
    assert by_array["run_id"].n_unique() == 12
    assert by_array.columns[-7:] == ["efficiency", "method", "steps", "rejected_steps",
                                     "rhs_evals", "jac_evals", "wall_time"][-7:]


def test_thread_count_does_not_change_results():
    sets = [{"c": c} for c in np.linspace(3e4, 7e4, 9)]
    one = hdw.simulate_many(sets, threads=1, metrics=["thz_amp"], **SHORT)
    two = hdw.simulate_many(sets, threads=2, metrics=["thz_amp"], **SHORT)
    assert one.drop("wall_time").equals(two.drop("wall_time"))


def test_base_parameters_apply_to_every_run():
    df = hdw.simulate_many([{"c": 5e4}, {"c": 6e4}], base={"Tc": 0.3}, metrics=["thz_amp"], **SHORT)
    assert df["Tc"].to_list() == [0.3, 0.3]


@pytest.mark.parametrize(
    "call, words",
    [
        (lambda: hdw.simulate_many([{"c": 1e4}, {"sigm0": 1.0}]), ["parameter set 1", "sigma0"]),
        (lambda: hdw.simulate_many(np.ones((3, 2)), names=["c"]), ["2 columns", "1 names"]),
        (lambda: hdw.simulate_many(np.ones((3, 2))), ["names="]),
        (lambda: hdw.simulate_many(np.ones((3, 2)), names=["c", "A2"]), ["unknown parameter 'A2'"]),
        (lambda: hdw.simulate_many(np.ones((3, 2)), names=["A", "mem_A"]), ["'mem_A' given twice"]),
        (lambda: hdw.simulate_many([{"c": 1e4}], metrics=["thz_amps"]), ["thz_amp"]),
        (lambda: hdw.simulate_many([{"c": 1e4}], threads=0), ["threads = 0"]),
        (lambda: hdw.simulate_many([{"c": 1e4}], base={"c": 0.0}), ["parameter 'c' = 0"]),
    ],
)
def test_bad_batches_are_value_errors(call, words):
    with pytest.raises(ValueError) as e:
        call()
    for w in words:
        assert w in str(e.value), (w, str(e.value))
