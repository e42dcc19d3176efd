//! Which part of a run the periodic metrics use, or why a run has none.

use crate::laws::input::Input;

/// The periodic window of a run: `(frequency [Hz], start [s], whole cycles)` at its end, or
/// the reason the run has none, in words a user reads next to a missing metric.
///
/// `freq` is the drive frequency (input's open loop, reference's closed loop); `input` is
/// the open-loop input (`None` in closed loop); `cycles` the whole cycles wanted.
pub fn periodic_window(
    freq: Option<f64>,
    input: Option<&Input>,
    t_end: f64,
    cycles: usize,
) -> Result<(f64, f64, usize), String> {
    let Some(f) = freq else {
        return Err(match input {
            Some(i) => format!(
                "the input ({}) is not periodic: periodic metrics need a sine or a recorded \
                 input that repeats",
                i.kind_name()
            ),
            None => "the reference is not periodic".to_string(),
        });
    };
    if let Some(Input::Recorded(p)) = input {
        let end = p.t.last().copied().unwrap_or(0.0);
        if end < t_end * (1.0 - 1e-9) {
            return Err(format!(
                "the recorded input ends at t = {end} s, before the run's end ({t_end} s)"
            ));
        }
    }
    let whole = (t_end * f + 1e-9).floor() as usize;
    let used = cycles.min(whole);
    if used == 0 {
        return Err(format!(
            "the run ({t_end} s) is shorter than one drive period ({} s)",
            1.0 / f
        ));
    }
    Ok((f, t_end - used as f64 / f, used))
}
