//! The determination's sentences made readable: many pairwise "not separable" sentences
//! that all say one thing (without a current, every torque scaled together) grouped into
//! one sentence naming that direction.

/// From this many pairwise "not separable" sentences on, they are grouped into one [–].
pub const GROUP_FROM: usize = 6;

/// The pair and correlation of a pairwise sentence of [`crate::drive::identifiability`]:
/// "a and b are not separable on this record (correlation r); …".
fn pair_of(s: &str) -> Option<(String, String, f64)> {
    let (names, rest) = s.split_once(" are not separable on this record (correlation ")?;
    let (a, b) = names.split_once(" and ")?;
    if a.contains(' ') || b.contains(' ') {
        return None;
    }
    let r: f64 = rest.split(')').next()?.trim().parse().ok()?;
    Some((a.to_string(), b.to_string(), r))
}

/// Replace [`GROUP_FROM`] or more pairwise "not separable" sentences in `sentences` by one,
/// at the first one's place, naming every parameter involved, the smallest |correlation| and
/// the torque-scale direction, where the records log no current (`has_current` false; with
/// a current they stay as they are).
pub fn group_pairs(sentences: &mut Vec<String>, has_current: bool) {
    let pairs: Vec<(usize, (String, String, f64))> =
        sentences.iter().enumerate().filter_map(|(k, s)| Some((k, pair_of(s)?))).collect();
    // With a current the pairs say different things, each worth its sentence.
    if pairs.len() < GROUP_FROM || has_current {
        return;
    }
    let mut names: Vec<String> = Vec::new();
    for (_, (a, b, _)) in &pairs {
        for n in [a, b] {
            if !names.contains(n) {
                names.push(n.clone());
            }
        }
    }
    let weakest = pairs.iter().map(|(_, p)| p.2.abs()).fold(f64::INFINITY, f64::min);
    let why = "without a current the encoders see every torque only relative to the motor's torque per volt Km/R: R scaled by 1/α and the inertias, damping, stiffness and friction scaled by α leave the motion as it was (the torque-scale direction); log the current, or fix Km (= Ke) and R from the motor's data sheet";
    let sentence = format!(
        "{} pairs of {} are not separable on this record (|correlation| ≥ {weakest:.4}): {why}.",
        pairs.len(),
        names.join(", ")
    );
    let first = pairs[0].0;
    let drop: Vec<usize> = pairs.iter().map(|(k, _)| *k).collect();
    let mut out = Vec::with_capacity(sentences.len());
    for (k, s) in sentences.drain(..).enumerate() {
        if k == first {
            out.push(sentence.clone());
        } else if !drop.contains(&k) {
            out.push(s);
        }
    }
    *sentences = out;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Ten pairwise sentences become one naming the torque scale; three stay as they are.
    #[test]
    fn pairs_are_grouped() {
        let names = ["R", "Jj", "Cj", "Jz", "Cz"];
        let mut s = vec!["first".to_string()];
        for (i, a) in names.iter().enumerate() {
            for b in &names[i + 1..] {
                s.push(format!("{a} and {b} are not separable on this record (correlation 0.9990); fix one or add an experiment that moves them differently."));
            }
        }
        s.push("last".into());
        group_pairs(&mut s, false);
        assert_eq!(s.len(), 3, "{s:?}");
        assert!(s[1].starts_with("10 pairs of R, Jj, Cj, Jz, Cz") && s[1].contains("torque-scale"));
        let mut few = s[..1].to_vec();
        few.push("a and b are not separable on this record (correlation -0.9990); fix one.".into());
        group_pairs(&mut few, false);
        assert_eq!(few.len(), 2);
        let mut with_current = s[..1].to_vec();
        with_current.extend(std::iter::repeat_n(few[1].clone(), 8));
        group_pairs(&mut with_current, true);
        assert_eq!(with_current.len(), 9);
    }
}
