//! Fleet files: the manifest of logs (a CSV or Parquet table, or a path pattern whose
//! fields become columns), timestamps as days, and the tables `fits.parquet` and
//! `drift.parquet` written with each column's unit and description in the metadata.
//!
//! The fit rows are committed in parts like a study's runs ([`crate::store`]'s
//! conventions: `parts/fits-TAG-SEQ.parquet`, then one merge, sorted by `run_index`, in
//! bounded memory), so a killed fleet keeps every finished log and `--shard K/N` slices
//! merge into the table one run gives.

use crate::atomic::{Staged, commit};
use crate::error::IoError;
use crate::table::Table;
use polars::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// One column of a fleet table: name, cells, unit, description.
pub struct FleetColumn {
    /// Column name.
    pub name: String,
    /// Cells.
    pub cells: FleetCells,
    /// Unit (`-` for none, `text` for text).
    pub unit: String,
    /// One line of description.
    pub doc: String,
}

/// Cells of a fleet column.
pub enum FleetCells {
    /// Numbers (NaN written as null).
    F64(Vec<f64>),
    /// Counts.
    U64(Vec<u64>),
    /// Flags.
    Bool(Vec<bool>),
    /// Text that may be missing.
    Text(Vec<Option<String>>),
}

impl FleetCells {
    fn len(&self) -> usize {
        match self {
            FleetCells::F64(v) => v.len(),
            FleetCells::U64(v) => v.len(),
            FleetCells::Bool(v) => v.len(),
            FleetCells::Text(v) => v.len(),
        }
    }
}

fn frame(cols: &[FleetColumn]) -> Result<DataFrame, PolarsError> {
    let columns: Vec<Column> = cols
        .iter()
        .map(|c| {
            let name: PlSmallStr = c.name.as_str().into();
            match &c.cells {
                FleetCells::F64(v) => {
                    let ca: Float64Chunked =
                        v.iter().map(|x| x.is_finite().then_some(*x)).collect();
                    Column::from(ca.with_name(name).into_series())
                }
                FleetCells::U64(v) => Column::new(name, v),
                FleetCells::Bool(v) => Column::new(name, v),
                FleetCells::Text(v) => Column::new(name, v),
            }
        })
        .collect();
    DataFrame::new_infer_height(columns)
}

/// Parquet key-value metadata: each field's unit and description, the same as one JSON
/// document under `hdw.columns`, and any `extra` document (e.g. `hdw.parameter_units`).
fn metadata(
    df: &DataFrame,
    docs: &[(String, String, String)],
    extra: &[(&str, String)],
) -> KeyValueMetadata {
    let mut arrow = df.schema().to_arrow(CompatLevel::newest());
    let mut doc = serde_json::Map::new();
    for (name, field) in arrow.iter_mut() {
        let Some((_, unit, text)) = docs.iter().find(|(n, _, _)| n == name.as_str()) else {
            continue;
        };
        let mut md = field.metadata.as_deref().cloned().unwrap_or_default();
        md.insert("unit".into(), unit.as_str().into());
        md.insert("description".into(), text.as_str().into());
        field.metadata = Some(Arc::new(md));
        doc.insert(name.to_string(), serde_json::json!({ "unit": unit, "description": text }));
    }
    let key = polars_parquet::write::schema_to_metadata_key(&arrow);
    let mut kv = vec![
        (key.key, key.value.unwrap_or_default()),
        (crate::parquet_out::COLUMNS_KEY.to_string(), serde_json::Value::Object(doc).to_string()),
    ];
    kv.extend(extra.iter().map(|(k, v)| (k.to_string(), v.clone())));
    KeyValueMetadata::from_static(kv)
}

/// Write `cols` to `path` (Parquet, atomically) with their units and descriptions.
pub fn write_fleet_table(
    path: &Path,
    cols: &[FleetColumn],
    extra: &[(&str, String)],
) -> Result<(), IoError> {
    if let Some(c) = cols.iter().find(|c| c.cells.len() != cols[0].cells.len()) {
        return Err(IoError::format(
            path,
            format!("column '{}' has another length (internal error)", c.name),
        ));
    }
    let mut df = frame(cols).map_err(IoError::polars(path, "cannot build the table"))?;
    let docs: Vec<(String, String, String)> =
        cols.iter().map(|c| (c.name.clone(), c.unit.clone(), c.doc.clone())).collect();
    let meta = metadata(&df, &docs, extra);
    crate::atomic::write_atomically(path, |file| {
        ParquetWriter::new(file)
            .with_key_value_metadata(Some(meta))
            .finish(&mut df)
            .map(|_| ())
            .map_err(IoError::polars(path, "cannot write Parquet"))
    })
}

/// Column docs `(name, unit, description)` and extra `hdw.*` metadata `(key, value)`.
type Docs = (Vec<(String, String, String)>, Vec<(String, String)>);

/// The column docs and extra metadata of a Parquet file written by [`write_fleet_table`].
fn read_docs(path: &Path) -> Result<Docs, IoError> {
    let f = std::fs::File::open(path).map_err(|e| IoError::fs(path, e))?;
    let mut reader = ParquetReader::new(f);
    let md = reader.get_metadata().map_err(IoError::polars(path, "cannot read Parquet"))?;
    let mut docs = Vec::new();
    let mut extra = Vec::new();
    for kv in md.key_value_metadata().as_deref().unwrap_or(&[]) {
        let value = kv.value.clone().unwrap_or_default();
        if kv.key == crate::parquet_out::COLUMNS_KEY {
            if let Ok(serde_json::Value::Object(m)) = serde_json::from_str(&value) {
                for (name, v) in m {
                    let s = |k: &str| v.get(k).and_then(|x| x.as_str()).unwrap_or("").to_string();
                    docs.push((name, s("unit"), s("description")));
                }
            }
        } else if kv.key.starts_with("hdw.") {
            extra.push((kv.key.clone(), value));
        }
    }
    Ok((docs, extra))
}

/// A fleet's fit rows in their folder: parts while the fleet runs, one table at the end.
pub struct FitStore {
    dir: PathBuf,
    tag: String,
    next_seq: usize,
}

impl FitStore {
    /// Open `dir` for shard `shard = Some((k, n))` or the whole fleet.
    pub fn open(dir: &Path, shard: Option<(usize, usize)>) -> Result<Self, IoError> {
        let tag = match shard {
            Some((k, n)) => format!("shard-{k}-of-{n}"),
            None => "all".to_string(),
        };
        let mut s = FitStore { dir: dir.to_path_buf(), tag, next_seq: 0 };
        s.next_seq = s.parts()?.len();
        Ok(s)
    }

    /// The final table of this shard (`fits.parquet` or `fits-shard-K-of-N.parquet`).
    pub fn fits_path(&self) -> PathBuf {
        shard_fits_path(&self.dir, &self.tag)
    }

    fn parts(&self) -> Result<Vec<PathBuf>, IoError> {
        list(&self.dir.join("parts"), &format!("fits-{}-", self.tag))
    }

    /// Whether this shard already has rows in the folder.
    pub fn has_results(&self) -> Result<bool, IoError> {
        Ok(self.fits_path().exists() || !self.parts()?.is_empty())
    }

    /// Call `visit(run_index, run_id)` for every committed row (final table and parts).
    /// Each file is read a row group at a time (two columns), with the eager reader.
    pub fn committed(&self, visit: &mut dyn FnMut(u64, &str)) -> Result<(), IoError> {
        let mut files = self.parts()?;
        if self.fits_path().exists() {
            files.insert(0, self.fits_path());
        }
        for f in &files {
            let mut offset = 0;
            for g in row_groups(f)? {
                let cols = Some(vec!["run_index".to_string(), "run_id".to_string()]);
                let df = read_rows(f, cols, offset, g)?;
                offset += g;
                let idx = run_indices(&df, f)?;
                let ids = df.column("run_id").map_err(IoError::polars(f, "no run_id column"))?;
                let ids = ids.str().map_err(IoError::polars(f, "run_id is not text"))?;
                for (i, id) in idx.into_iter().zip(ids.iter()) {
                    visit(i, id.unwrap_or(""));
                }
            }
        }
        Ok(())
    }

    /// Commit rows as one part (all or nothing).
    pub fn commit(
        &mut self,
        cols: &[FleetColumn],
        extra: &[(&str, String)],
    ) -> Result<(), IoError> {
        if cols.first().is_none_or(|c| c.cells.len() == 0) {
            return Ok(());
        }
        let parts = self.dir.join("parts");
        let path = loop {
            let p = parts.join(format!("fits-{}-{:06}.parquet", self.tag, self.next_seq));
            self.next_seq += 1;
            if !p.exists() {
                break p;
            }
        };
        write_fleet_table(&path, cols, extra)
    }

    /// Merge the final table and the parts into the final table; remove the parts.
    /// Returns the number of rows.
    pub fn finish(&mut self) -> Result<usize, IoError> {
        let parts = self.parts()?;
        let mut inputs = Vec::new();
        if self.fits_path().exists() {
            inputs.push(self.fits_path());
        }
        inputs.extend(parts.iter().cloned());
        let n = merge_with_docs(&inputs, &self.fits_path())?;
        for f in &parts {
            std::fs::remove_file(f).map_err(|e| IoError::fs(f, e))?;
        }
        let _ = std::fs::remove_dir(self.dir.join("parts"));
        Ok(n)
    }
}

fn shard_fits_path(dir: &Path, tag: &str) -> PathBuf {
    if tag == "all" { dir.join("fits.parquet") } else { dir.join(format!("fits-{tag}.parquet")) }
}

fn list(dir: &Path, prefix: &str) -> Result<Vec<PathBuf>, IoError> {
    let entries = match std::fs::read_dir(dir) {
        Ok(e) => e,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(IoError::fs(dir, e)),
    };
    let mut files: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with(prefix) && n.ends_with(".parquet"))
        })
        .collect();
    files.sort();
    Ok(files)
}

/// The shard tables `fits-shard-K-of-N.parquet` in `dir`.
pub fn shard_tables(dir: &Path) -> Result<Vec<PathBuf>, IoError> {
    list(dir, "fits-shard-")
}

/// Rows a fleet merge holds at once, and the rows per row group of `fits.parquet` [rows]:
/// small enough that merging stays flat in the fleet's size (a window of 2 048 rows is
/// about 500 logs of four parameters), large enough that a query reads few row groups.
pub const MERGE_WINDOW_ROWS: u64 = 2048;

/// Row-group sizes of a Parquet file [rows].
fn row_groups(path: &Path) -> Result<Vec<usize>, IoError> {
    let f = std::fs::File::open(path).map_err(|e| IoError::fs(path, e))?;
    let md = ParquetReader::new(f)
        .get_metadata()
        .map_err(IoError::polars(path, "cannot read Parquet"))?
        .clone();
    Ok(md.row_groups.iter().map(|g| g.num_rows()).collect())
}

/// Rows `[from, from + len)` of `path` (whole row groups decode; `columns` None: all).
fn read_rows(
    path: &Path,
    columns: Option<Vec<String>>,
    from: usize,
    len: usize,
) -> Result<DataFrame, IoError> {
    let f = std::fs::File::open(path).map_err(|e| IoError::fs(path, e))?;
    ParquetReader::new(f)
        .with_columns(columns)
        .with_slice(Some((from, len)))
        .finish()
        .map_err(IoError::polars(path, "cannot read Parquet"))
}

fn run_indices(df: &DataFrame, path: &Path) -> Result<Vec<u64>, IoError> {
    let c = df
        .column("run_index")
        .and_then(|c| c.cast(&DataType::UInt64))
        .map_err(IoError::polars(path, "no run_index column"))?;
    let ca = c.u64().map_err(IoError::polars(path, "run_index is not a count"))?;
    Ok(ca.iter().map(|v| v.unwrap_or(u64::MAX)).collect())
}

/// One input of a merge, read a row group at a time from where the last window ended.
struct Cursor {
    path: PathBuf,
    groups: Vec<usize>,
    next: usize,
    offset: usize,
    /// Rows read but not yet handed out (all at or after the last window's end).
    pending: Option<DataFrame>,
    /// First and last run index, rows.
    range: Option<(u64, u64, u64)>,
}

impl Cursor {
    /// Open `path`: its row groups and run-index range (the run_index column streamed).
    fn open(path: &Path) -> Result<Self, IoError> {
        let groups = row_groups(path)?;
        let (mut lo, mut hi, mut n, mut prev) = (u64::MAX, 0u64, 0u64, 0u64);
        let mut offset = 0;
        for &g in &groups {
            let df = read_rows(path, Some(vec!["run_index".into()]), offset, g)?;
            for v in run_indices(&df, path)? {
                if n > 0 && v < prev {
                    return Err(IoError::format(path, "rows not sorted by run_index"));
                }
                prev = v;
                lo = lo.min(v);
                hi = hi.max(v);
                n += 1;
            }
            offset += g;
        }
        let range = (n > 0).then_some((lo, hi, n));
        Ok(Cursor { path: path.to_path_buf(), groups, next: 0, offset: 0, pending: None, range })
    }

    /// The rows with run index below `b` not yet handed out (the input is sorted).
    fn take_below(&mut self, b: u64) -> Result<Option<DataFrame>, IoError> {
        let mut out: Option<DataFrame> = None;
        loop {
            let df = match self.pending.take() {
                Some(df) => df,
                None if self.next < self.groups.len() => {
                    let g = self.groups[self.next];
                    self.next += 1;
                    let df = read_rows(&self.path, None, self.offset, g)?;
                    self.offset += g;
                    df
                }
                None => break,
            };
            let idx = run_indices(&df, &self.path)?;
            let split = idx.partition_point(|&v| v < b);
            let (head, rest) = (df.slice(0, split), df.slice(split as i64, idx.len() - split));
            if head.height() > 0 {
                match out.as_mut() {
                    None => out = Some(head),
                    Some(o) => {
                        o.vstack_mut(&head)
                            .map_err(IoError::polars(&self.path, "columns differ"))?;
                    }
                }
            }
            if rest.height() > 0 {
                self.pending = Some(rest);
                break;
            }
        }
        Ok(out)
    }
}

/// Merge `inputs` (fit tables or parts, each sorted by `run_index`, same columns) into
/// `out`: one row per `run_id` (the first in input order), sorted by `run_index`, with the
/// first input's units and descriptions. Streamed by windows of run indices of about
/// [`MERGE_WINDOW_ROWS`] rows: each input is read a row group at a time from where the
/// last window left it, and each window is written as one row group, so memory holds a
/// window and a row group per input being read, however large the fleet. Returns the
/// number of rows.
pub fn merge_with_docs(inputs: &[PathBuf], out: &Path) -> Result<usize, IoError> {
    if inputs.is_empty() {
        return Ok(0);
    }
    let (docs, extra) = read_docs(&inputs[0])?;
    let extra: Vec<(&str, String)> = extra.iter().map(|(k, v)| (k.as_str(), v.clone())).collect();
    let mut cursors = Vec::with_capacity(inputs.len());
    let (mut lo, mut hi, mut rows) = (u64::MAX, 0u64, 0u64);
    for f in inputs {
        let c = Cursor::open(f)?;
        if let Some((a, b, n)) = c.range {
            lo = lo.min(a);
            hi = hi.max(b);
            rows += n;
        }
        cursors.push(c);
    }
    let span = if rows == 0 { 1 } else { hi - lo + 1 };
    let width = (span as u128 * MERGE_WINDOW_ROWS as u128 / rows.max(1) as u128).max(1) as u64;
    let mut staged = Staged::new(out)?;
    let written = staged.write_with(|file| {
        let mut writer = None;
        let mut written = 0usize;
        let mut a = lo;
        while rows > 0 && a <= hi {
            let b = a.saturating_add(width);
            let mut window: Option<DataFrame> = None;
            for c in cursors.iter_mut() {
                let Some((fa, fb, _)) = c.range else { continue };
                if fb < a || fa >= b {
                    continue;
                }
                let Some(part) = c.take_below(b)? else { continue };
                match window.as_mut() {
                    None => window = Some(part),
                    Some(w) => {
                        w.vstack_mut(&part).map_err(IoError::polars(
                            &c.path,
                            "columns differ from the other parts",
                        ))?;
                    }
                }
            }
            if let Some(w) = window {
                let mut w = dedupe_and_sort(w, out)?;
                if w.height() > 0 {
                    if writer.is_none() {
                        let meta = metadata(&w, &docs, &extra);
                        writer = Some(
                            ParquetWriter::new(&mut *file)
                                .with_key_value_metadata(Some(meta))
                                .batched(&w.schema().clone())
                                .map_err(IoError::polars(out, "cannot write Parquet"))?,
                        );
                    }
                    w.rechunk_mut();
                    written += w.height();
                    if let Some(bw) = writer.as_mut() {
                        bw.write_batch(&w).map_err(IoError::polars(out, "cannot write Parquet"))?;
                    }
                }
            }
            // An input done with is closed (its last row group dropped).
            for c in cursors.iter_mut() {
                if c.range.is_some_and(|(_, fb, _)| fb < b) {
                    c.pending = None;
                }
            }
            if b > hi {
                break;
            }
            a = b;
        }
        match writer {
            Some(bw) => {
                bw.finish().map(|_| ()).map_err(IoError::polars(out, "cannot write Parquet"))?
            }
            None => {
                // No rows: the first input's (empty) table, with its columns.
                let mut df = read_rows(&inputs[0], None, 0, 0)?;
                let meta = metadata(&df, &docs, &extra);
                ParquetWriter::new(&mut *file)
                    .with_key_value_metadata(Some(meta))
                    .finish(&mut df)
                    .map_err(IoError::polars(out, "cannot write Parquet"))?;
            }
        }
        Ok(written)
    })?;
    commit(vec![staged], &[])?;
    Ok(written)
}

/// Drop repeated run ids (the first kept) and sort by run_index.
fn dedupe_and_sort(df: DataFrame, out: &Path) -> Result<DataFrame, IoError> {
    let ids = df.column("run_id").map_err(IoError::polars(out, "no run_id column"))?;
    let ca = ids.str().map_err(IoError::polars(out, "run_id is not text"))?;
    let mut seen = std::collections::HashSet::new();
    let mask: BooleanChunked = ca.iter().map(|id| Some(seen.insert(id.unwrap_or("")))).collect();
    let df = df.filter(&mask).map_err(IoError::polars(out, "cannot drop repeated runs"))?;
    df.sort(["run_index"], SortMultipleOptions::default().with_maintain_order(true))
        .map_err(IoError::polars(out, "cannot sort by run_index"))
}

/// Write a fleet table to `path` (Parquet, atomically) in batches: `fill` is handed a
/// sink that takes one batch of columns at a time (same names and kinds every time; the
/// first batch's units and descriptions go into the metadata), so the table never has to
/// be held whole. A batch without rows still fixes the columns of an empty table.
pub fn write_fleet_table_batched(
    path: &Path,
    extra: &[(&str, String)],
    fill: impl FnOnce(&mut dyn FnMut(&[FleetColumn]) -> Result<(), IoError>) -> Result<(), IoError>,
) -> Result<(), IoError> {
    crate::atomic::write_atomically(path, |file| {
        let mut file = Some(file);
        let mut writer = None;
        let mut empty: Option<(DataFrame, KeyValueMetadata)> = None;
        let mut sink = |cols: &[FleetColumn]| -> Result<(), IoError> {
            if let Some(c) = cols.iter().find(|c| c.cells.len() != cols[0].cells.len()) {
                return Err(IoError::format(
                    path,
                    format!("column '{}' has another length (internal error)", c.name),
                ));
            }
            let mut df = frame(cols).map_err(IoError::polars(path, "cannot build the table"))?;
            let meta = || {
                let docs: Vec<(String, String, String)> =
                    cols.iter().map(|c| (c.name.clone(), c.unit.clone(), c.doc.clone())).collect();
                metadata(&df, &docs, extra)
            };
            if df.height() == 0 {
                if writer.is_none() && empty.is_none() {
                    empty = Some((df.clone(), meta()));
                }
                return Ok(());
            }
            if writer.is_none() {
                let m = meta();
                let f = file.take().ok_or_else(|| IoError::format(path, "written twice"))?;
                writer = Some(
                    ParquetWriter::new(f)
                        .with_key_value_metadata(Some(m))
                        .batched(&df.schema().clone())
                        .map_err(IoError::polars(path, "cannot write Parquet"))?,
                );
                empty = None;
            }
            df.rechunk_mut();
            if let Some(w) = writer.as_mut() {
                w.write_batch(&df).map_err(IoError::polars(path, "cannot write Parquet"))?;
            }
            Ok(())
        };
        fill(&mut sink)?;
        match (writer, empty, file) {
            (Some(w), _, _) => {
                w.finish().map(|_| ()).map_err(IoError::polars(path, "cannot write Parquet"))
            }
            (None, Some((mut df, meta)), Some(f)) => ParquetWriter::new(f)
                .with_key_value_metadata(Some(meta))
                .finish(&mut df)
                .map(|_| ())
                .map_err(IoError::polars(path, "cannot write Parquet")),
            _ => Err(IoError::format(path, "no columns to write (internal error)")),
        }
    })
}

/// Read the named columns of a Parquet file (those it has) a few row groups at a time (at
/// least `rows` rows, whole row groups), handing each piece to `each` in file order, with
/// polars' eager reader: memory follows the piece, and nothing stays behind between the
/// pieces (a lazy scan per piece left a few MB per pass). A file without rows gives no piece.
pub fn for_each_piece(
    path: &Path,
    names: &[&str],
    rows: usize,
    mut each: impl FnMut(&Table) -> Result<(), IoError>,
) -> Result<(), IoError> {
    let open = || std::fs::File::open(path).map_err(|e| IoError::fs(path, e));
    let mut reader = ParquetReader::new(open()?);
    let schema = reader.schema().map_err(IoError::polars(path, "cannot read Parquet"))?;
    let present: Vec<String> =
        names.iter().filter(|n| schema.contains(n)).map(|n| n.to_string()).collect();
    let md = reader.get_metadata().map_err(IoError::polars(path, "cannot read Parquet"))?;
    let groups: Vec<usize> = md.row_groups.iter().map(|g| g.num_rows()).collect();
    let mut offset = 0;
    let mut k = 0;
    while k < groups.len() {
        let mut len = 0;
        while k < groups.len() && (len == 0 || len + groups[k] <= rows.max(1)) {
            len += groups[k];
            k += 1;
        }
        if len == 0 {
            continue;
        }
        let df = ParquetReader::new(open()?)
            .with_columns(Some(present.clone()))
            .with_slice(Some((offset, len)))
            .finish()
            .map_err(IoError::polars(path, "cannot read Parquet"))?;
        each(&crate::table::frame_to_table(&df, path)?)?;
        offset += len;
    }
    Ok(())
}

mod days;
mod pattern;
pub use days::{format_day, parse_day};
pub use pattern::expand_pattern;
