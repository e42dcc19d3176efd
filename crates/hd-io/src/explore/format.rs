//! Rendering query results as an aligned text table, CSV, Markdown or JSON.
//!
//! A [`Report`] is a few facts (source, row count, …) and one or more titled tables.
//! Text and Markdown show everything, with units in the headers; JSON holds the facts and
//! every table (as arrays of row objects, missing values as `null`); CSV holds only the
//! last table, the main result, with plain column names.

use crate::table::{ColumnData, Table};
use serde_json::{Map, Value, json};

/// One titled table of a report.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Section {
    /// Key of the table in JSON output, e.g. `metrics`.
    pub key: String,
    /// Title shown above the table.
    pub title: String,
    /// The data.
    pub table: Table,
    /// Unit of each column (empty: none shown), parallel to `table.names`.
    pub units: Vec<String>,
}

/// The answer to one query: facts and tables.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Report {
    /// Named facts, in order (e.g. `rows`, `failed`).
    pub facts: Vec<(String, Value)>,
    /// The tables; the last one is the main result.
    pub sections: Vec<Section>,
}

impl Report {
    /// A fact by name.
    pub fn fact(&self, name: &str) -> Option<&Value> {
        self.facts.iter().find(|(n, _)| n == name).map(|(_, v)| v)
    }

    /// A table by its key.
    pub fn section(&self, key: &str) -> Option<&Section> {
        self.sections.iter().find(|s| s.key == key)
    }
}

/// Output formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Aligned text for the terminal.
    Table,
    /// Comma-separated values of the main table.
    Csv,
    /// GitHub-flavoured Markdown.
    Markdown,
    /// One JSON object.
    Json,
}

/// Render `report` in `format`.
pub fn render(report: &Report, format: Format) -> String {
    match format {
        Format::Table => render_text(report),
        Format::Markdown => render_markdown(report),
        Format::Csv => report.sections.last().map(|s| render_csv(&s.table)).unwrap_or_default(),
        Format::Json => {
            serde_json::to_string_pretty(&render_json(report)).unwrap_or_default() + "\n"
        }
    }
}

/// A number as every hdw table prints it: [`hd_text::number`] (about six significant
/// digits, whole numbers exactly, never a digit dropped).
pub fn short_number(x: f64) -> String {
    hd_text::number(x)
}

/// Cell text for people: short numbers, `—` for missing values.
fn cell(data: &ColumnData, row: usize) -> String {
    match data {
        ColumnData::Num(v) if v[row].is_nan() => "—".into(),
        ColumnData::Num(v) => short_number(v[row]),
        ColumnData::Text(v) => v[row].clone().unwrap_or_else(|| "—".into()),
    }
}

fn header(name: &str, unit: Option<&String>) -> String {
    match unit {
        Some(u) if !u.is_empty() => format!("{name} [{u}]"),
        _ => name.to_string(),
    }
}

fn fact_text(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        Value::Array(a) => a.iter().map(fact_text).collect::<Vec<_>>().join(", "),
        other => other.to_string(),
    }
}

fn render_text(report: &Report) -> String {
    let mut out = String::new();
    for (name, v) in &report.facts {
        out += &format!("{name}: {}\n", fact_text(v));
    }
    for s in &report.sections {
        if !out.is_empty() {
            out.push('\n');
        }
        out += &format!("{}\n", s.title);
        out += &text_table(s);
    }
    out
}

/// Columns padded to their widest cell; numbers right-aligned, text left-aligned.
fn text_table(s: &Section) -> String {
    let t = &s.table;
    let heads: Vec<String> =
        t.names.iter().enumerate().map(|(k, n)| header(n, s.units.get(k))).collect();
    // Row by row.
    let cells: Vec<Vec<String>> =
        (0..t.height).map(|r| t.columns.iter().map(|c| cell(c, r)).collect()).collect();
    let mut widths: Vec<usize> = heads.iter().map(|h| h.chars().count()).collect();
    for row in &cells {
        for (w, c) in widths.iter_mut().zip(row) {
            *w = (*w).max(c.chars().count());
        }
    }
    let pad = |text: &str, k: usize| {
        let fill = " ".repeat(widths[k] - text.chars().count());
        match t.columns[k] {
            ColumnData::Num(_) => format!("{fill}{text}"),
            ColumnData::Text(_) => format!("{text}{fill}"),
        }
    };
    let line = |row: Vec<String>| row.join("  ").trim_end().to_string() + "\n";
    let mut out = line(heads.iter().enumerate().map(|(k, h)| pad(h, k)).collect());
    out += &line(widths.iter().map(|w| "-".repeat(*w)).collect());
    for row in &cells {
        out += &line(row.iter().enumerate().map(|(k, c)| pad(c, k)).collect());
    }
    out
}

fn render_markdown(report: &Report) -> String {
    let mut out = String::new();
    for (name, v) in &report.facts {
        out += &format!("- **{name}**: {}\n", fact_text(v).replace('|', "\\|"));
    }
    for s in &report.sections {
        let t = &s.table;
        out += &format!("\n### {}\n\n", s.title);
        let heads: Vec<String> =
            t.names.iter().enumerate().map(|(k, n)| header(n, s.units.get(k))).collect();
        out += &format!("| {} |\n", heads.join(" | "));
        let rules: Vec<&str> = t
            .columns
            .iter()
            .map(|c| if matches!(c, ColumnData::Num(_)) { "---:" } else { "---" })
            .collect();
        out += &format!("| {} |\n", rules.join(" | "));
        for r in 0..t.height {
            let row: Vec<String> =
                t.columns.iter().map(|c| cell(c, r).replace('|', "\\|")).collect();
            out += &format!("| {} |\n", row.join(" | "));
        }
    }
    out
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// CSV with full-precision numbers and empty fields for missing values.
fn render_csv(t: &Table) -> String {
    let mut out = t.names.iter().map(|n| csv_field(n)).collect::<Vec<_>>().join(",") + "\n";
    for r in 0..t.height {
        let row: Vec<String> = t
            .columns
            .iter()
            .map(|c| match c {
                ColumnData::Num(v) if v[r].is_nan() => String::new(),
                ColumnData::Num(v) => format!("{}", v[r]),
                ColumnData::Text(v) => v[r].as_deref().map(csv_field).unwrap_or_default(),
            })
            .collect();
        out += &(row.join(",") + "\n");
    }
    out
}

/// The rows of a table as JSON objects; NaN becomes null.
pub fn table_json(t: &Table) -> Value {
    let rows: Vec<Value> = (0..t.height)
        .map(|r| {
            let mut obj = Map::new();
            for (name, c) in t.names.iter().zip(&t.columns) {
                let v = match c {
                    ColumnData::Num(v) if v[r].is_finite() => json!(v[r]),
                    ColumnData::Num(_) => Value::Null,
                    ColumnData::Text(v) => json!(v[r]),
                };
                obj.insert(name.clone(), v);
            }
            Value::Object(obj)
        })
        .collect();
    Value::Array(rows)
}

fn render_json(report: &Report) -> Value {
    let mut obj = Map::new();
    for (name, v) in &report.facts {
        obj.insert(name.clone(), v.clone());
    }
    for s in &report.sections {
        obj.insert(s.key.clone(), table_json(&s.table));
        if s.units.iter().any(|u| !u.is_empty()) {
            let units: Map<String, Value> =
                s.table.names.iter().cloned().zip(s.units.iter().map(|u| json!(u))).collect();
            obj.insert(format!("{}_units", s.key), Value::Object(units));
        }
    }
    Value::Object(obj)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn short_numbers() {
        assert_eq!(short_number(500000.0), "500000");
        assert_eq!(short_number(0.0123456789), "0.0123457");
        assert_eq!(short_number(1.5), "1.5");
        assert_eq!(short_number(2.5e-5), "2.5e-5");
        assert_eq!(short_number(1.23e7 + 0.5), "1.23e7");
        // The pivot's row keys: a trailing zero of the integer part is a digit.
        assert_eq!(short_number(142_510.27), "142510");
        assert_eq!(short_number(744_380.4), "744380");
    }

    #[test]
    fn csv_quotes_and_blanks() {
        let t = Table {
            names: vec!["a".into(), "b".into()],
            columns: vec![
                ColumnData::Num(vec![1.0, f64::NAN]),
                ColumnData::Text(vec![Some("x,y".into()), None]),
            ],
            height: 2,
        };
        assert_eq!(render_csv(&t), "a,b\n1,\"x,y\"\n,\n");
    }
}
