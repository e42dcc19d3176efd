//! Timestamps of a fleet's logs as days since 1970-01-01 (proleptic Gregorian), and back.

/// Days since 1970-01-01 of a civil date (proleptic Gregorian).
fn days_from_civil(y: i64, m: u32, d: u32) -> i64 {
    let y = if m <= 2 { y - 1 } else { y };
    let era = if y >= 0 { y } else { y - 399 } / 400;
    let yoe = y - era * 400;
    let mp = (m as i64 + 9) % 12;
    let doy = (153 * mp + 2) / 5 + d as i64 - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

fn days_in_month(y: i64, m: u32) -> u32 {
    match m {
        1 | 3 | 5 | 7 | 8 | 10 | 12 => 31,
        4 | 6 | 9 | 11 => 30,
        _ if (y % 4 == 0 && y % 100 != 0) || y % 400 == 0 => 29,
        _ => 28,
    }
}

/// A timestamp as days since 1970-01-01 [days]: `YYYY-MM-DD`, `YYYYMMDD`, with an
/// optional time `THH:MM[:SS[.fff]]` (or a space instead of `T`, a trailing `Z`), or a
/// plain number (already days). The error says what was expected.
pub fn parse_day(text: &str) -> Result<f64, String> {
    let s = text.trim();
    let bad = || {
        format!(
            "'{text}' is not a timestamp: expected YYYY-MM-DD, YYYYMMDD or YYYY-MM-DDTHH:MM[:SS], or a number of days"
        )
    };
    let (date, time) = match s.find(['T', ' ']) {
        Some(i) => (&s[..i], Some(s[i + 1..].trim_end_matches('Z'))),
        None => (s, None),
    };
    let ymd: Option<(i64, u32, u32)> =
        if date.len() == 8 && date.bytes().all(|b| b.is_ascii_digit()) && time.is_none() {
            (|| Some((date[..4].parse().ok()?, date[4..6].parse().ok()?, date[6..].parse().ok()?)))(
            )
        } else {
            let p: Vec<&str> = date.split('-').collect();
            if p.len() == 3 && p[0].len() == 4 {
                match (p[0].parse(), p[1].parse(), p[2].parse()) {
                    (Ok(y), Ok(m), Ok(d)) => Some((y, m, d)),
                    _ => None,
                }
            } else {
                None
            }
        };
    let Some((y, m, d)) = ymd else {
        return match s.parse::<f64>() {
            Ok(v) if v.is_finite() && time.is_none() => Ok(v),
            _ => Err(bad()),
        };
    };
    if !(1..=12).contains(&m) || d < 1 || d > days_in_month(y, m) {
        return Err(format!("'{text}': no such date (month 1-12, day within the month)"));
    }
    let mut day = days_from_civil(y, m, d) as f64;
    if let Some(t) = time {
        let p: Vec<&str> = t.split(':').collect();
        let num = |k: usize| p.get(k).map_or(Ok(0.0), |v| v.parse::<f64>());
        match (p.len(), num(0), num(1), num(2)) {
            (2 | 3, Ok(h), Ok(mi), Ok(sec)) if h < 24.0 && mi < 60.0 && sec < 61.0 => {
                day += (h * 3600.0 + mi * 60.0 + sec) / 86_400.0;
            }
            _ => return Err(bad()),
        }
    }
    Ok(day)
}

/// The date of a day number, `YYYY-MM-DD` (for labels).
pub fn format_day(day: f64) -> String {
    let z = day.floor() as i64 + 719_468;
    let era = if z >= 0 { z } else { z - 146_096 } / 146_097;
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!("{y:04}-{m:02}-{d:02}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timestamps_parse_to_days_and_back() {
        assert_eq!(parse_day("1970-01-01").unwrap(), 0.0);
        assert_eq!(parse_day("2000-03-01").unwrap(), 11_017.0);
        assert_eq!(parse_day("20000301").unwrap(), 11_017.0);
        assert_eq!(parse_day("2000-03-01T12:00").unwrap(), 11_017.5);
        assert_eq!(parse_day("2000-03-01 06:00:00Z").unwrap(), 11_017.25);
        assert_eq!(parse_day("12.5").unwrap(), 12.5);
        assert_eq!(format_day(11_017.9), "2000-03-01");
        assert_eq!(format_day(parse_day("2024-02-29").unwrap()), "2024-02-29");
        assert!(parse_day("2023-02-29").unwrap_err().contains("no such date"));
        assert!(parse_day("yesterday").unwrap_err().contains("expected YYYY-MM-DD"));
    }
}
