//! `series.parquet` of a drive fit (`hdw fit drive`): the measured and simulated outputs
//! behind every score, one row per record, model, output and sample, so that any metric can
//! be computed again with polars or DuckDB (`GROUP BY experiment, model, output`). Like
//! every Parquet file the workbench writes, each column carries its unit and description in
//! the field metadata and in the file-level `hdw.columns` document; the output columns'
//! unit depends on the row's `output` (given in `unit`), and their metadata lists it for
//! each output the file holds.

use crate::atomic::write_atomically;
use crate::error::IoError;
use crate::parquet_out::COLUMNS_KEY;
use polars::prelude::*;
use std::path::Path;
use std::sync::Arc;

/// Name, unit and description of each column of `series.parquet`, in file order. A unit
/// `by output` is filled in from the outputs the file holds.
pub const SERIES_COLUMNS: &[(&str, &str, &str)] = &[
    ("experiment", "", "record name: the configuration's [[experiment]] name, or validation"),
    ("set", "", "estimation (a fitted record) or validation (scored only)"),
    ("model", "", "the model simulated: the friction law of a rigid fit, or compliant"),
    ("sample", "-", "sample index in the record, from 0"),
    ("t", "s", "time of the sample as recorded"),
    (
        "output",
        "",
        "the output compared: force, position (rigid); motor, load, current, command (compliant)",
    ),
    ("unit", "", "unit of measured, simulated and residual on this row"),
    (
        "measured",
        "by output",
        "the recorded output (force: the nominal gain times the recorded command)",
    ),
    ("simulated", "by output", "the fitted model's output, simulated over the whole record"),
    ("residual", "by output", "measured minus simulated"),
    ("scored", "-", "true where the configuration's [score] rule counts the sample"),
];

/// The rows of `series.parquet`, column by column.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FitSeries {
    /// Record name per row.
    pub experiment: Vec<String>,
    /// `estimation` or `validation` per row.
    pub set: Vec<String>,
    /// Model name per row.
    pub model: Vec<String>,
    /// Sample index per row [–].
    pub sample: Vec<u64>,
    /// Time per row [s].
    pub t: Vec<f64>,
    /// Output name per row.
    pub output: Vec<String>,
    /// Unit of the row's values.
    pub unit: Vec<String>,
    /// Recorded value [unit].
    pub measured: Vec<f64>,
    /// Simulated value [unit].
    pub simulated: Vec<f64>,
    /// Whether the score rule counts the row.
    pub scored: Vec<bool>,
}

/// One output of one record, to be appended to a [`FitSeries`].
#[derive(Clone, Debug)]
pub struct SeriesBlock<'a> {
    /// Record name.
    pub experiment: &'a str,
    /// `estimation` or `validation`.
    pub set: &'a str,
    /// Model name.
    pub model: &'a str,
    /// Output name.
    pub output: &'a str,
    /// Output unit.
    pub unit: &'a str,
    /// Sample times [s].
    pub t: &'a [f64],
    /// Recorded values [unit].
    pub measured: &'a [f64],
    /// Simulated values [unit].
    pub simulated: &'a [f64],
    /// The samples the score rule counts.
    pub scored: std::ops::Range<usize>,
}

impl FitSeries {
    /// Append one output of one record (the shortest of `t`, `measured`, `simulated`).
    pub fn push(&mut self, b: SeriesBlock) {
        let n = b.t.len().min(b.measured.len()).min(b.simulated.len());
        let text = |v: &mut Vec<String>, s: &str| v.extend(std::iter::repeat_n(s.to_string(), n));
        text(&mut self.experiment, b.experiment);
        text(&mut self.set, b.set);
        text(&mut self.model, b.model);
        text(&mut self.output, b.output);
        text(&mut self.unit, b.unit);
        self.sample.extend(0..n as u64);
        self.t.extend_from_slice(&b.t[..n]);
        self.measured.extend_from_slice(&b.measured[..n]);
        self.simulated.extend_from_slice(&b.simulated[..n]);
        self.scored.extend((0..n).map(|k| b.scored.contains(&k)));
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether there are no rows.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// `output: unit` of each output, in order of first appearance.
    fn units(&self) -> String {
        let mut seen: Vec<(String, String)> = Vec::new();
        for (o, u) in self.output.iter().zip(&self.unit) {
            if !seen.iter().any(|(a, _)| a == o) {
                seen.push((o.clone(), u.clone()));
            }
        }
        seen.iter().map(|(o, u)| format!("{o}: {u}")).collect::<Vec<_>>().join(", ")
    }

    fn frame(&self) -> PolarsResult<DataFrame> {
        let residual: Vec<f64> =
            self.measured.iter().zip(&self.simulated).map(|(m, s)| m - s).collect();
        DataFrame::new_infer_height(vec![
            Column::new("experiment".into(), &self.experiment),
            Column::new("set".into(), &self.set),
            Column::new("model".into(), &self.model),
            Column::new("sample".into(), &self.sample),
            Column::new("t".into(), &self.t),
            Column::new("output".into(), &self.output),
            Column::new("unit".into(), &self.unit),
            Column::new("measured".into(), &self.measured),
            Column::new("simulated".into(), &self.simulated),
            Column::new("residual".into(), residual),
            Column::new("scored".into(), &self.scored),
        ])
    }
}

/// Write `s` to `path` as Parquet, atomically, with each column's unit and description.
pub fn write_fit_series(path: &Path, s: &FitSeries) -> Result<(), IoError> {
    let mut df = s.frame().map_err(IoError::polars(path, "cannot build the series table"))?;
    let meta = series_metadata(&df, &s.units());
    write_atomically(path, |file| {
        ParquetWriter::new(file)
            .with_key_value_metadata(Some(meta))
            .finish(&mut df)
            .map(|_| ())
            .map_err(IoError::polars(path, "cannot write Parquet"))
    })
}

/// Rows of a streamed `series.parquet` per row group: about 25 MB in memory while one is
/// written (half the rows of the groups the whole table was cut into, 262 144, which
/// compress about 10 % better).
pub const SERIES_CHUNK: usize = 131_072;

/// The record, set, model, output and unit of the rows that follow in a [`SeriesStream`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SeriesKey {
    /// Record name.
    pub experiment: String,
    /// `estimation` or `validation`.
    pub set: String,
    /// Model name.
    pub model: String,
    /// Output name.
    pub output: String,
    /// Output unit.
    pub unit: String,
}

/// The file a streamed series goes to (buffered, see [`crate::atomic::Staged::write_with`]).
type Sink<'a, 'f> = &'a mut std::io::BufWriter<&'f mut std::fs::File>;

/// `series.parquet` written while its rows are produced ([`stream_fit_series`]): every
/// [`SERIES_CHUNK`] rows become one row group, so memory does not grow with the records.
pub struct SeriesStream<'a, 'f> {
    path: &'a Path,
    units: &'a str,
    file: Option<Sink<'a, 'f>>,
    writer: Option<polars::io::parquet::write::BatchedWriter<Sink<'a, 'f>>>,
    /// Runs of rows sharing a key: (key, rows).
    keys: Vec<(SeriesKey, usize)>,
    sample: Vec<u64>,
    t: Vec<f64>,
    measured: Vec<f64>,
    simulated: Vec<f64>,
    scored: Vec<bool>,
    failed: Option<IoError>,
}

impl SeriesStream<'_, '_> {
    /// Start the rows of `key` (the rows pushed next belong to it).
    pub fn begin(&mut self, key: &SeriesKey) {
        self.keys.push((key.clone(), 0));
    }

    /// One row of the current key: sample index, time [s], measured and simulated values,
    /// whether the score rule counts it.
    pub fn push(&mut self, sample: usize, t: f64, measured: f64, simulated: f64, scored: bool) {
        if self.failed.is_some() {
            return;
        }
        if let Some(k) = self.keys.last_mut() {
            k.1 += 1;
        }
        self.sample.push(sample as u64);
        self.t.push(t);
        self.measured.push(measured);
        self.simulated.push(simulated);
        self.scored.push(scored);
        if self.t.len() >= SERIES_CHUNK
            && let Err(e) = self.flush()
        {
            self.failed = Some(e);
        }
    }

    /// Write the rows held as one row group (the first creates the writer).
    fn flush(&mut self) -> Result<(), IoError> {
        let path = self.path;
        if self.t.is_empty() {
            return Ok(());
        }
        let text = |f: fn(&SeriesKey) -> &str| -> Vec<&str> {
            self.keys.iter().flat_map(|(k, n)| std::iter::repeat_n(f(k), *n)).collect()
        };
        let residual: Vec<f64> =
            self.measured.iter().zip(&self.simulated).map(|(m, s)| m - s).collect();
        let strings = [
            text(|k| &k.experiment),
            text(|k| &k.set),
            text(|k| &k.model),
            text(|k| &k.output),
            text(|k| &k.unit),
        ];
        let [experiment, set, model, output, unit] =
            strings.map(|v| Series::new("".into(), v).into_column());
        // The numeric columns move into the table (no second copy).
        let take = |v: &mut Vec<f64>| std::mem::replace(v, Vec::with_capacity(SERIES_CHUNK));
        let mut df = DataFrame::new_infer_height(vec![
            experiment.with_name("experiment".into()),
            set.with_name("set".into()),
            model.with_name("model".into()),
            Column::new(
                "sample".into(),
                std::mem::replace(&mut self.sample, Vec::with_capacity(SERIES_CHUNK)),
            ),
            Column::new("t".into(), take(&mut self.t)),
            output.with_name("output".into()),
            unit.with_name("unit".into()),
            Column::new("measured".into(), take(&mut self.measured)),
            Column::new("simulated".into(), take(&mut self.simulated)),
            Column::new("residual".into(), residual),
            Column::new(
                "scored".into(),
                std::mem::replace(&mut self.scored, Vec::with_capacity(SERIES_CHUNK)),
            ),
        ])
        .map_err(IoError::polars(path, "cannot build the series table"))?;
        if self.writer.is_none()
            && let Some(file) = self.file.take()
        {
            let meta = series_metadata(&df, self.units);
            let w = ParquetWriter::new(file)
                .with_key_value_metadata(Some(meta))
                .batched(&df.schema().clone())
                .map_err(IoError::polars(path, "cannot write Parquet"))?;
            self.writer = Some(w);
        }
        // The key of the last run goes on into the next row group.
        let last = self.keys.pop().map(|(k, _)| (k, 0));
        self.keys.clear();
        self.keys.extend(last);
        df.rechunk_mut();
        match self.writer.as_mut() {
            Some(w) => w.write_batch(&df).map_err(IoError::polars(path, "cannot write Parquet")),
            None => Ok(()),
        }
    }
}

/// Write `series.parquet` to `path` (atomically, with the rest of a
/// [`crate::atomic::group`]) while `produce` makes its rows: the same table, column
/// metadata and file-level document as [`write_fit_series`] of the same rows, in row
/// groups of [`SERIES_CHUNK`] rows. `units` is the measured columns' unit, `output: unit`
/// for each output in order of first appearance (e.g. `force: N, position: m`). A write
/// error stops the writing and is returned once `produce` is done. At least one row must
/// be produced.
pub fn stream_fit_series<T>(
    path: &Path,
    units: &str,
    produce: impl FnOnce(&mut SeriesStream) -> T,
) -> Result<T, IoError> {
    write_atomically(path, |file| {
        let mut st = SeriesStream {
            path,
            units,
            file: Some(file),
            writer: None,
            keys: Vec::new(),
            sample: Vec::with_capacity(SERIES_CHUNK),
            t: Vec::with_capacity(SERIES_CHUNK),
            measured: Vec::with_capacity(SERIES_CHUNK),
            simulated: Vec::with_capacity(SERIES_CHUNK),
            scored: Vec::with_capacity(SERIES_CHUNK),
            failed: None,
        };
        let out = produce(&mut st);
        if let Some(e) = st.failed.take() {
            return Err(e);
        }
        st.flush()?;
        match st.writer.take() {
            Some(w) => w.finish().map_err(IoError::polars(path, "cannot write Parquet"))?,
            None => return Err(IoError::format(path, "no rows to write (internal error)")),
        };
        Ok(out)
    })
}

/// The key-value metadata of `series.parquet` for the table `df` (its schema) with the
/// measured columns in `units`: the Arrow schema with each field's unit and description,
/// and the `hdw.columns` document.
fn series_metadata(df: &DataFrame, units: &str) -> KeyValueMetadata {
    let mut arrow = df.schema().to_arrow(CompatLevel::newest());
    let mut doc = serde_json::Map::new();
    for (name, field) in arrow.iter_mut() {
        let Some((_, unit, description)) = SERIES_COLUMNS.iter().find(|c| c.0 == name.as_str())
        else {
            continue;
        };
        let unit = if *unit == "by output" { units } else { unit };
        let mut md = field.metadata.as_deref().cloned().unwrap_or_default();
        md.insert("unit".into(), unit.into());
        md.insert("description".into(), (*description).into());
        field.metadata = Some(Arc::new(md));
        doc.insert(name.to_string(), serde_json::json!({"unit": unit, "description": description}));
    }
    let key = polars_parquet::write::schema_to_metadata_key(&arrow);
    KeyValueMetadata::from_static(vec![
        (key.key, key.value.unwrap_or_default()),
        (COLUMNS_KEY.to_string(), serde_json::Value::Object(doc).to_string()),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The table as docs/columns.md gives it.
    fn markdown() -> String {
        let mut t = String::from("| column | unit | meaning |\n|---|---|---|\n");
        for (n, u, d) in SERIES_COLUMNS {
            t += &format!("| `{n}` | {} | {d} |\n", if u.is_empty() { "text" } else { u });
        }
        t
    }

    #[test]
    fn columns_md_documents_the_series_table() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/columns.md");
        let doc = std::fs::read_to_string(path).unwrap();
        assert!(
            doc.contains(&markdown()),
            "docs/columns.md lacks the series table:\n{}",
            markdown()
        );
    }

    /// The streamed file holds the same table and metadata as the file written whole
    /// (rows across several row groups, a key that spans two of them).
    #[test]
    fn streamed_series_equal_the_whole_table() {
        let dir = tempfile::tempdir().unwrap();
        let n = SERIES_CHUNK + 1000;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let m: Vec<f64> = t.iter().map(|t| t.sin()).collect();
        let sim: Vec<f64> = t.iter().map(|t| 0.9 * t.sin()).collect();
        let outputs = [("force", "N"), ("position", "m")];
        let mut whole = FitSeries::default();
        for (output, unit) in outputs {
            whole.push(SeriesBlock {
                experiment: "estimation",
                set: "estimation",
                model: "coulomb-viscous",
                output,
                unit,
                t: &t,
                measured: &m,
                simulated: &sim,
                scored: 49..n,
            });
        }
        let a = dir.path().join("a.parquet");
        write_fit_series(&a, &whole).unwrap();
        let b = dir.path().join("b.parquet");
        stream_fit_series(&b, "force: N, position: m", |st| {
            for (output, unit) in outputs {
                st.begin(&SeriesKey {
                    experiment: "estimation".into(),
                    set: "estimation".into(),
                    model: "coulomb-viscous".into(),
                    output: output.into(),
                    unit: unit.into(),
                });
                for k in 0..n {
                    st.push(k, t[k], m[k], sim[k], (49..n).contains(&k));
                }
            }
        })
        .unwrap();
        let (fa, fb) = (crate::read_frame(&a).unwrap(), crate::read_frame(&b).unwrap());
        assert!(fa.equals_missing(&fb));
        let kv = |p: &Path| {
            let mut r = ParquetReader::new(std::fs::File::open(p).unwrap());
            r.get_metadata().unwrap().key_value_metadata().clone().unwrap()
        };
        assert_eq!(kv(&a), kv(&b));
    }

    #[test]
    fn series_read_back_with_polars_and_their_units() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("series.parquet");
        let mut s = FitSeries::default();
        let t = [0.0, 1e-3, 2e-3, 3e-3];
        let block = |output, unit, m: &'static [f64], sim: &'static [f64]| SeriesBlock {
            experiment: "estimation",
            set: "estimation",
            model: "lugre",
            output,
            unit,
            t: &[],
            measured: m,
            simulated: sim,
            scored: 1..4,
        };
        s.push(SeriesBlock {
            t: &t,
            ..block("force", "N", &[1.0, 2.0, 3.0, 4.0], &[1.0, 2.5, 3.0, 3.0])
        });
        s.push(SeriesBlock { t: &t, ..block("position", "m", &[0.1, 0.2, 0.3, 0.4], &[0.1; 4]) });
        write_fit_series(&path, &s).unwrap();

        let df = crate::read_frame(&path).unwrap();
        let names: Vec<&str> = df.get_column_names().iter().map(|n| n.as_str()).collect();
        let expected: Vec<&str> = SERIES_COLUMNS.iter().map(|c| c.0).collect();
        assert_eq!(names, expected);
        // The force's residual over the scored samples, by polars' own query.
        let rss = df
            .lazy()
            .filter(col("output").eq(lit("force")).and(col("scored")))
            .select([(col("residual") * col("residual")).sum()])
            .collect()
            .unwrap();
        let v = rss.column("residual").unwrap().f64().unwrap().get(0).unwrap();
        assert!((v - 1.25).abs() < 1e-12, "{v}");
        // Units and descriptions in the file-level document.
        let file = std::fs::File::open(&path).unwrap();
        let mut reader = ParquetReader::new(file);
        let kv = reader.get_metadata().unwrap().key_value_metadata().clone().unwrap();
        let doc = kv.iter().find(|k| k.key == COLUMNS_KEY).unwrap().value.clone().unwrap();
        let doc: serde_json::Value = serde_json::from_str(&doc).unwrap();
        assert_eq!(doc["t"]["unit"], "s");
        assert_eq!(doc["measured"]["unit"], "force: N, position: m");
        assert!(doc["scored"]["description"].as_str().unwrap().contains("[score]"));
    }
}
