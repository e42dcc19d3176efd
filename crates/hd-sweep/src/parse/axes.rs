//! Checking grid axes and their values.

use super::Checker;
use crate::axis::{Knob, Value, linspace, logspace};
use crate::design::Axis;
use crate::error::StudyError;
use crate::spec::*;
use hd_model::Input;
use toml::Spanned;

impl Checker<'_> {
    pub(super) fn axis(&self, s: &Spanned<AxisSpec>, input: &Input) -> Result<Axis, StudyError> {
        let a = s.get_ref();
        let at = a.name.span().start;
        let key = format!("axis '{}'", a.name.get_ref());
        let knob = self.knob(&a.name, "axis.name", input)?;
        let given = [a.values.is_some(), a.linspace.is_some(), a.logspace.is_some()]
            .iter()
            .filter(|b| **b)
            .count();
        if given != 1 {
            return Err(self.err(at, &key, "expected exactly one of values, linspace, logspace"));
        }
        let values: Vec<Value> = if let Some(vals) = &a.values {
            vals.iter().map(|v| self.value(knob, v, at, &key)).collect::<Result<_, _>>()?
        } else {
            let (r, log) = a
                .linspace
                .map(|r| (r, false))
                .or(a.logspace.map(|r| (r, true)))
                .expect("one range");
            if log && !(r.start > 0.0 && r.stop > 0.0) {
                return Err(self.err(
                    at,
                    &key,
                    format!(
                        "logspace needs start > 0 and stop > 0, got {} and {}",
                        r.start, r.stop
                    ),
                ));
            }
            let xs = if log {
                logspace(r.start, r.stop, r.num)
            } else {
                linspace(r.start, r.stop, r.num)
            };
            xs.into_iter()
                .map(|x| knob.check(x).map(|_| Value::Num(x)).map_err(|e| self.err(at, &key, e)))
                .collect::<Result<_, _>>()?
        };
        if values.is_empty() {
            return Err(self.err(at, &key, "empty axis: expected at least one value"));
        }
        // A repeated value would plan two runs with one run_id: the table would hold one
        // of them and a resumed sweep would never count the study as done.
        if let Some((j, k)) = first_repeat(&values) {
            return Err(self.err(
                at,
                &key,
                format!(
                    "values {} and {} are the same ({}): each value may appear once",
                    j + 1,
                    k + 1,
                    describe(&values[k])
                ),
            ));
        }
        Ok(Axis { knob, values, zip: a.zip.clone() })
    }

    fn value(
        &self,
        knob: Knob,
        v: &toml::Value,
        at: usize,
        key: &str,
    ) -> Result<Value, StudyError> {
        match (knob, v) {
            (Knob::Variant, toml::Value::String(s)) => {
                s.parse().map(Value::Variant).map_err(|e: String| self.err(at, key, e))
            }
            (Knob::Variant, other) => Err(self.err(
                at,
                key,
                format!("{other}: expected a variant name (linear, damped, full)"),
            )),
            (Knob::Stiffness, toml::Value::String(s)) => {
                s.parse().map(Value::Stiffness).map_err(|e: String| self.err(at, key, e))
            }
            (Knob::Compensation, toml::Value::String(s)) => {
                s.parse().map(Value::Compensation).map_err(|e: String| self.err(at, key, e))
            }
            (Knob::Feedback, toml::Value::String(s)) => {
                s.parse().map(Value::Feedback).map_err(|e: String| self.err(at, key, e))
            }
            (Knob::Compensation | Knob::Feedback | Knob::Stiffness, other) => {
                Err(self.err(at, key, format!("{other}: expected a name, not a number")))
            }
            (_, toml::Value::Float(x)) => {
                knob.check(*x).map(|_| Value::Num(*x)).map_err(|e| self.err(at, key, e))
            }
            (_, toml::Value::Integer(i)) => knob
                .check(*i as f64)
                .map(|_| Value::Num(*i as f64))
                .map_err(|e| self.err(at, key, e)),
            (_, other) => Err(self.err(at, key, format!("{other}: expected a number"))),
        }
    }
}

/// The positions (0-based, first < second) of the first pair of equal values, found by
/// sorting (an axis may have millions of values).
fn first_repeat(values: &[Value]) -> Option<(usize, usize)> {
    let key = |v: &Value| match v {
        Value::Num(x) => format!("n{:016x}", (x + 0.0).to_bits()),
        other => format!("{other:?}"),
    };
    let mut keyed: Vec<(String, usize)> =
        values.iter().enumerate().map(|(k, v)| (key(v), k)).collect();
    keyed.sort();
    keyed.windows(2).filter(|w| w[0].0 == w[1].0).map(|w| (w[0].1, w[1].1)).min_by_key(|&(_, k)| k)
}

/// A value as written in a message.
fn describe(v: &Value) -> String {
    match v {
        Value::Num(x) => format!("{x:e}"),
        other => format!("{other:?}").to_lowercase(),
    }
}
