//! Reading named numeric columns from a recorded data file — delimited text (`.csv`,
//! `.tsv`, `.txt`) or Parquet — checking every value.
//!
//! Text files are read by a small reader of its own rather than by type inference: only the
//! asked columns are looked at, and each of their cells is parsed as a number on its own,
//! so an unused column may hold anything and a column that starts with integers and turns
//! to decimals further down reads as it should. The dialect (separator, comments, BOM,
//! quotes) is guessed by [`crate::csv_sniff`].

use crate::csv_sniff::{self, decode_line, is_skipped, sniff_separator, split_fields, strip_bom};
use crate::error::IoError;
use polars::prelude::*;
use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::Path;

/// The kinds of file understood.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum FileKind {
    /// Delimited text with a header row.
    Text,
    /// Apache Parquet.
    Parquet,
    /// MATLAB MAT v5 (variables as columns).
    Mat,
}

/// The file's kind from its extension, after checking it exists.
fn file_kind(path: &Path) -> Result<FileKind, IoError> {
    if path.is_dir() {
        return Err(IoError::format(path, "is a folder: expected a data file"));
    }
    if !path.is_file() {
        return Err(IoError::fs(
            path,
            std::io::Error::new(std::io::ErrorKind::NotFound, "no such file"),
        ));
    }
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    match ext.as_str() {
        "parquet" | "pq" => Ok(FileKind::Parquet),
        "csv" | "tsv" | "txt" | "dat" => {
            refuse_binary(path)?;
            Ok(FileKind::Text)
        }
        "mat" => Ok(FileKind::Mat),
        _ => Err(IoError::format(
            path,
            format!(
                "unknown file type '.{ext}': expected delimited text (.csv, .tsv, .txt, .dat), .parquet or .mat"
            ),
        )),
    }
}

/// Refuse a text-named file whose first bytes say it is compressed or binary (its bytes
/// would otherwise end up in an error message about its header).
fn refuse_binary(path: &Path) -> Result<(), IoError> {
    use std::io::Read;
    let mut head = Vec::with_capacity(4096);
    File::open(path)
        .and_then(|f| f.take(4096).read_to_end(&mut head))
        .map_err(|e| IoError::fs(path, e))?;
    match hd_model::text_file::binary_kind(&head) {
        Some(kind) => Err(IoError::format(path, format!("is {kind}: expected delimited text"))),
        None => Ok(()),
    }
}

/// Read a delimited text file (header row; comma, tab or semicolon guessed from the header;
/// `#` comment lines skipped) or a Parquet file, chosen by extension, into a frame. Column
/// types of text files are inferred from every row, so a column whose decimals start late
/// is a float column.
pub fn read_frame(path: &Path) -> Result<DataFrame, IoError> {
    match file_kind(path)? {
        FileKind::Parquet => File::open(path).map_err(|e| IoError::fs(path, e)).and_then(|f| {
            let mut reader = ParquetReader::new(f);
            let schema = reader.schema().map_err(IoError::polars(path, "cannot read Parquet"))?;
            refuse_decimals(path, &schema)?;
            reader.finish().map_err(IoError::polars(path, "cannot read Parquet"))
        }),
        FileKind::Mat => Err(IoError::format(
            path,
            "a MAT file is read by variable (read_columns), not as a table",
        )),
        FileKind::Text => {
            let sep = sniff_file_separator(path)?;
            CsvReadOptions::default()
                .with_has_header(true)
                .with_infer_schema_length(None)
                .map_parse_options(|o| {
                    o.with_separator(sep)
                        .with_comment_prefix(Some(csv_sniff::COMMENT_PREFIX.to_string().as_str()))
                })
                .try_into_reader_with_file_path(Some(path.to_path_buf()))
                .and_then(|r| r.finish())
                .map_err(IoError::polars(path, "cannot read delimited text"))
        }
    }
}

/// Read the named columns as `f64`, in the order asked; nothing else in the file is looked
/// at. A MAT v5 file (`.mat`) gives its variables of those names ([`crate::mat`]). Text cells are trimmed and parsed one by one (integers, decimals and exponents mix
/// freely; with a tab or semicolon separator a decimal comma `1,5` is accepted too);
/// Parquet columns of any integer or float type are cast, and text columns parsed (boolean
/// and decimal columns are refused, naming the column).
///
/// Errors name the file and: a missing column (listing those present); or the column, the
/// 1-based data row (header and comment lines not counted) and the cell that is empty, not
/// a number, NaN or infinite.
pub fn read_columns(path: &Path, names: &[&str]) -> Result<Vec<Vec<f64>>, IoError> {
    match file_kind(path)? {
        FileKind::Text => read_text_columns(path, names),
        FileKind::Parquet => read_parquet_columns(path, names),
        FileKind::Mat => crate::mat::read_mat_vectors(path, names),
    }
}

/// Read a recorded voltage profile (columns `t` [s] and `u` [V], strictly increasing t).
pub fn read_profile(path: &Path) -> Result<hd_model::Profile, IoError> {
    let mut cols = read_columns(path, &["t", "u"])?;
    let u = cols.pop().unwrap_or_default();
    let t = cols.pop().unwrap_or_default();
    hd_model::Profile::new(t, u, "recorded input").map_err(|e| IoError::format(path, e.to_string()))
}

/// The error for a column that is not in the file, listing those that are (and pointing
/// at a near match differing only in case or surrounding blanks).
fn missing_column(path: &Path, name: &str, present: &[String]) -> IoError {
    let near = present.iter().find(|p| p.trim().eq_ignore_ascii_case(name.trim()));
    let hint = near.map_or(String::new(), |p| format!("; did you mean '{p}'?"));
    IoError::format(path, format!("missing column '{name}' (found: {}){hint}", present.join(", ")))
}

/// Why a cell is not a usable number.
enum CellProblem {
    /// Nothing but blanks.
    Empty,
    /// Not a number.
    NotANumber,
    /// NaN or ±infinity.
    NonFinite,
}

/// Parse one cell: trimmed, then as a Rust `f64` literal; when `decimal_comma`, a cell
/// with one comma and no point is read with the comma as the decimal mark.
fn parse_cell(cell: &str, decimal_comma: bool) -> Result<f64, CellProblem> {
    let s = cell.trim();
    if s.is_empty() {
        return Err(CellProblem::Empty);
    }
    let v = match s.parse::<f64>() {
        Ok(v) => v,
        Err(_) if decimal_comma && !s.contains('.') && s.matches(',').count() == 1 => {
            s.replacen(',', ".", 1).parse::<f64>().map_err(|_| CellProblem::NotANumber)?
        }
        Err(_) => return Err(CellProblem::NotANumber),
    };
    if v.is_finite() { Ok(v) } else { Err(CellProblem::NonFinite) }
}

/// The message for a bad cell.
fn cell_message(name: &str, row: usize, cell: &str, problem: CellProblem) -> String {
    let shown: String = cell.trim().chars().take(40).collect();
    match problem {
        CellProblem::Empty => format!("column '{name}', row {row}: empty cell; expected a number"),
        CellProblem::NotANumber => {
            format!("column '{name}', row {row}: '{shown}' is not a number")
        }
        CellProblem::NonFinite => {
            format!("column '{name}', row {row}: '{shown}' is not a finite number")
        }
    }
}

/// Open a text file for line-by-line reading.
fn open_text(path: &Path) -> Result<BufReader<File>, IoError> {
    File::open(path).map(|f| BufReader::with_capacity(1 << 16, f)).map_err(|e| IoError::fs(path, e))
}

/// Read the next line that is neither blank nor a comment into `buf`; returns its 1-based
/// line number, or `None` at the end of the file. `line_no` counts every line read.
fn next_content_line(
    path: &Path,
    reader: &mut impl BufRead,
    buf: &mut Vec<u8>,
    line_no: &mut usize,
) -> Result<Option<usize>, IoError> {
    loop {
        buf.clear();
        let n = reader.read_until(b'\n', buf).map_err(|e| IoError::fs(path, e))?;
        if n == 0 {
            return Ok(None);
        }
        *line_no += 1;
        if !is_skipped(&decode_line(buf)) {
            return Ok(Some(*line_no));
        }
    }
}

/// The separator of a delimited text file, guessed from its header line.
fn sniff_file_separator(path: &Path) -> Result<u8, IoError> {
    let mut reader = open_text(path)?;
    let (mut buf, mut line_no) = (Vec::new(), 0);
    if next_content_line(path, &mut reader, &mut buf, &mut line_no)?.is_none() {
        return Ok(b',');
    }
    let header = decode_line(&buf).into_owned();
    let mut data = Vec::new();
    let first = next_content_line(path, &mut reader, &mut data, &mut line_no)?
        .map(|_| decode_line(&data).into_owned());
    Ok(sniff_separator(strip_bom(&header), first.as_deref()))
}

/// A printable name for a separator.
fn separator_name(sep: u8) -> &'static str {
    match sep {
        b'\t' => "tab",
        b';' => "semicolon",
        _ => "comma",
    }
}

/// [`read_columns`] for delimited text.
fn read_text_columns(path: &Path, names: &[&str]) -> Result<Vec<Vec<f64>>, IoError> {
    let mut reader = open_text(path)?;
    let (mut buf, mut line_no) = (Vec::new(), 0usize);
    let Some(header_line) = next_content_line(path, &mut reader, &mut buf, &mut line_no)? else {
        return Err(IoError::format(
            path,
            "no header row: the file is empty or holds only comment lines; expected a header row naming the columns",
        ));
    };
    let header = decode_line(&buf).into_owned();
    let header = strip_bom(&header);

    // The first data line helps only to settle a tie between separators.
    let mut pending = Vec::new();
    let first_data = next_content_line(path, &mut reader, &mut pending, &mut line_no)?;
    let first_text = first_data.map(|_| decode_line(&pending).into_owned());
    let sep = sniff_separator(header, first_text.as_deref());
    let decimal_comma = sep != b',';

    let mut fields = Vec::new();
    split_fields(header, sep, &mut fields).map_err(|q| {
        IoError::format(
            path,
            format!(
                "line {header_line} (header): the quote opening field {} is not closed",
                q.field + 1
            ),
        )
    })?;
    let present: Vec<String> = fields.iter().map(|f| f.trim().to_string()).collect();
    drop(fields);

    // Where each asked column is.
    let mut index = Vec::with_capacity(names.len());
    for &name in names {
        let mut hits = present.iter().enumerate().filter(|(_, p)| *p == name.trim());
        let Some((k, _)) = hits.next() else {
            let mut err = missing_column(path, name, &present);
            if present.len() == 1
                && let IoError::Format { message, .. } = &mut err
            {
                message.push_str(
                    "; the header is a single column: expected comma, tab or semicolon separators",
                );
            }
            return Err(err);
        };
        if let Some((k2, _)) = hits.next() {
            return Err(IoError::format(
                path,
                format!(
                    "column '{name}' appears twice in the header (fields {} and {}); expected unique names",
                    k + 1,
                    k2 + 1
                ),
            ));
        }
        index.push(k);
    }
    let needed = index.iter().copied().max().map_or(0, |m| m + 1);

    let mut out: Vec<Vec<f64>> = vec![Vec::with_capacity(1024); names.len()];
    let mut row = 0usize;
    let mut current = first_data;
    let mut line = pending;
    while let Some(file_line) = current {
        row += 1;
        let text = decode_line(&line);
        let at = |msg: String| IoError::format(path, format!("{msg} (line {file_line})"));
        let mut f = Vec::with_capacity(present.len());
        split_fields(&text, sep, &mut f).map_err(|q| {
            at(format!("row {row}: the quote opening field {} is not closed", q.field + 1))
        })?;
        if f.len() < needed {
            let (k, name) = index
                .iter()
                .zip(names)
                .find(|(k, _)| **k >= f.len())
                .map_or((needed - 1, names[0]), |(k, n)| (*k, *n));
            return Err(at(format!(
                "column '{name}', row {row}: missing; the row has {} {}-separated field(s) but the column is field {} of {} in the header",
                f.len(),
                separator_name(sep),
                k + 1,
                present.len()
            )));
        }
        // More fields than the header (a decimal comma in a comma-separated file) shift
        // the values of the row; empty fields past the header's are trailing separators.
        if f.len() > present.len() && f[present.len()..].iter().any(|x| !x.trim().is_empty()) {
            return Err(at(format!(
                "row {row}: {} {}-separated fields but the header has {}; a decimal comma in a comma-separated file? (quote such values or use ';' as separator)",
                f.len(),
                separator_name(sep),
                present.len()
            )));
        }
        for ((col, &k), &name) in out.iter_mut().zip(&index).zip(names) {
            let cell = &f[k];
            match parse_cell(cell, decimal_comma) {
                Ok(v) => col.push(v),
                Err(p) => return Err(at(cell_message(name, row, cell, p))),
            }
        }
        drop(f);
        drop(text);
        current = next_content_line(path, &mut reader, &mut line, &mut line_no)?;
    }
    Ok(out)
}

/// How an error names a decimal column's values.
const DECIMALS: &str = "fixed-point decimals";

/// What a Parquet column of type `dtype` holds when it is not numbers a fit can read: a
/// decimal type (its conversion is not built in, and a measurement is not a decimal) or
/// true/false values (a torque read as 0/1 fits to nonsense).
fn not_numbers(dtype: &ArrowDataType) -> Option<&'static str> {
    match dtype {
        ArrowDataType::Decimal(..)
        | ArrowDataType::Decimal32(..)
        | ArrowDataType::Decimal64(..)
        | ArrowDataType::Decimal256(..) => Some(DECIMALS),
        ArrowDataType::Boolean => Some("true/false values"),
        _ => None,
    }
}

/// Refuse a Parquet file with a decimal column before it is read whole (this build reads
/// no decimal type), naming the column.
pub fn refuse_decimals(path: &Path, schema: &ArrowSchema) -> Result<(), IoError> {
    for (name, field) in schema.iter() {
        if not_numbers(field.dtype()) == Some(DECIMALS) {
            return Err(IoError::format(
                path,
                format!(
                    "column '{name}' holds {DECIMALS} ({:?}), which hdw does not read: cast it to float64 (or to text)",
                    field.dtype()
                ),
            ));
        }
    }
    Ok(())
}

/// [`read_columns`] for Parquet: only the asked columns are decoded.
fn read_parquet_columns(path: &Path, names: &[&str]) -> Result<Vec<Vec<f64>>, IoError> {
    let file = File::open(path).map_err(|e| IoError::fs(path, e))?;
    let mut reader = ParquetReader::new(file);
    let schema = reader.schema().map_err(IoError::polars(path, "cannot read Parquet"))?;
    let present: Vec<String> = schema.iter_names().map(|s| s.to_string()).collect();
    let mut projection = Vec::with_capacity(names.len());
    for &name in names {
        let k = present
            .iter()
            .position(|p| p == name)
            .ok_or_else(|| missing_column(path, name, &present))?;
        if let Some(field) = schema.get(name)
            && let Some(what) = not_numbers(field.dtype())
        {
            return Err(IoError::format(
                path,
                format!(
                    "column '{name}' holds {what} ({:?}): expected numbers (floating-point or integer; cast the column to float64)",
                    field.dtype()
                ),
            ));
        }
        projection.push(k);
    }
    projection.sort_unstable();
    projection.dedup();
    let df = reader
        .with_projection(Some(projection))
        .finish()
        .map_err(IoError::polars(path, "cannot read Parquet"))?;
    names
        .iter()
        .map(|&name| {
            let col = df.column(name).map_err(|_| missing_column(path, name, &present))?;
            let dtype = col.dtype().clone();
            if dtype == DataType::String {
                let ca = col.str().map_err(IoError::polars(path, "a text column"))?;
                return ca
                    .iter()
                    .enumerate()
                    .map(|(r, v)| {
                        let cell = v.unwrap_or("");
                        parse_cell(cell, false)
                            .map_err(|p| IoError::format(path, cell_message(name, r + 1, cell, p)))
                    })
                    .collect();
            }
            if !dtype.is_primitive_numeric() {
                return Err(IoError::format(
                    path,
                    format!("column '{name}': expected numbers, found {dtype}"),
                ));
            }
            let cast = col.cast(&DataType::Float64).map_err(|_| {
                IoError::format(path, format!("column '{name}': expected numbers, found {dtype}"))
            })?;
            let ca = cast.f64().map_err(IoError::polars(path, "a numeric column"))?;
            let mut out = Vec::with_capacity(ca.len());
            for (r, v) in ca.iter().enumerate() {
                match v {
                    Some(x) if x.is_finite() => out.push(x),
                    Some(x) => {
                        return Err(IoError::format(
                            path,
                            cell_message(name, r + 1, &x.to_string(), CellProblem::NonFinite),
                        ));
                    }
                    None => {
                        return Err(IoError::format(
                            path,
                            format!("column '{name}', row {}: null; expected a number", r + 1),
                        ));
                    }
                }
            }
            Ok(out)
        })
        .collect()
}
