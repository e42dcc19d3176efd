//! Reading numeric variables from MATLAB MAT files of version 5 (the default of `save` up to
//! `-v7`, which is the same layout with zlib-compressed elements).
//!
//! The layout: a 128-byte header (text, then a version and a two-byte endian mark `IM`
//! or `MI`), followed by data elements, each an 8-byte tag (type, byte count; or the
//! 4-byte "small element" form) and its bytes padded to 8. A variable is one `miMATRIX`
//! element, possibly wrapped in an `miCOMPRESSED` one; inside it come the array flags (the
//! class), the dimensions, the name and the real part. Only real numeric classes (double,
//! single, the integer classes, logical) are read, into `f64`, column-major and flattened;
//! a struct, cell, char, sparse or complex variable is reported as such. MAT v7.3 files are
//! HDF5 and are told apart by their header.

use crate::error::IoError;
use std::io::Read;
use std::path::Path;

/// One numeric variable of a MAT file.
#[derive(Clone, Debug, PartialEq)]
pub struct MatVariable {
    /// The variable's name.
    pub name: String,
    /// Its dimensions (rows, columns, …).
    pub dims: Vec<usize>,
    /// Its values, column-major [the variable's own units].
    pub data: Vec<f64>,
}

impl MatVariable {
    /// Whether it is a vector (or a scalar): at most one dimension above 1.
    pub fn is_vector(&self) -> bool {
        self.dims.iter().filter(|&&d| d > 1).count() <= 1
    }

    /// Its dimensions as `24841×1`.
    pub fn shape(&self) -> String {
        self.dims.iter().map(|d| d.to_string()).collect::<Vec<_>>().join("×")
    }
}

/// What a variable of the file is, for the listing of what a file holds.
#[derive(Clone, Debug, PartialEq)]
enum Entry {
    /// A real numeric array.
    Numeric(MatVariable),
    /// Anything else: its name and a description of its class.
    Other { name: String, what: String },
}

impl Entry {
    fn name(&self) -> &str {
        match self {
            Entry::Numeric(v) => &v.name,
            Entry::Other { name, .. } => name,
        }
    }
}

/// Byte order of the file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Order {
    Little,
    Big,
}

/// A cursor over a byte slice with the file's byte order; reads past the end are errors.
struct Cursor<'a> {
    bytes: &'a [u8],
    at: usize,
    order: Order,
}

impl<'a> Cursor<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len()).ok_or_else(|| {
            format!("truncated: an element needs {n} bytes at offset {} but the data ends", self.at)
        })?;
        let s = &self.bytes[self.at..end];
        self.at = end;
        Ok(s)
    }

    fn u32(&mut self) -> Result<u32, String> {
        let b: [u8; 4] = self.take(4)?.try_into().map_err(|_| "short read".to_string())?;
        Ok(match self.order {
            Order::Little => u32::from_le_bytes(b),
            Order::Big => u32::from_be_bytes(b),
        })
    }

    /// The next element: its type and its bytes (the cursor then stands after its padding).
    fn element(&mut self) -> Result<(u32, &'a [u8]), String> {
        let first = self.u32()?;
        if first >> 16 != 0 {
            // Small element: type in the low half, byte count (≤ 4) in the high half.
            let (ty, n) = (first & 0xffff, (first >> 16) as usize);
            if n > 4 {
                return Err(format!("small element of {n} bytes (at most 4 allowed)"));
            }
            let data = self.take(4)?;
            return Ok((ty, &data[..n]));
        }
        let n = self.u32()? as usize;
        let data = self.take(n)?;
        if first != MI_COMPRESSED {
            let pad = (8 - n % 8) % 8;
            self.at = (self.at + pad).min(self.bytes.len());
        }
        Ok((first, data))
    }
}

const MI_INT8: u32 = 1;
const MI_UINT8: u32 = 2;
const MI_INT16: u32 = 3;
const MI_UINT16: u32 = 4;
const MI_INT32: u32 = 5;
const MI_UINT32: u32 = 6;
const MI_SINGLE: u32 = 7;
const MI_DOUBLE: u32 = 9;
const MI_INT64: u32 = 12;
const MI_UINT64: u32 = 13;
const MI_MATRIX: u32 = 14;
const MI_COMPRESSED: u32 = 15;
const MI_UTF8: u32 = 16;

/// The name of an array class, for messages.
fn class_name(class: u32) -> &'static str {
    match class {
        1 => "a cell array",
        2 => "a struct",
        3 => "an object",
        4 => "a char array (text)",
        5 => "a sparse matrix",
        6 => "double",
        7 => "single",
        8 => "int8",
        9 => "uint8",
        10 => "int16",
        11 => "uint16",
        12 => "int32",
        13 => "uint32",
        14 => "int64",
        15 => "uint64",
        16 => "a function handle",
        17 => "an opaque object",
        _ => "of an unknown class",
    }
}

/// Decode the numbers of an element of data type `ty` into `f64`.
fn numbers(ty: u32, b: &[u8], order: Order) -> Result<Vec<f64>, String> {
    macro_rules! decode {
        ($t:ty, $n:expr) => {
            b.chunks_exact($n)
                .map(|c| {
                    let a: [u8; $n] = c.try_into().expect("chunk of the element's width");
                    (match order {
                        Order::Little => <$t>::from_le_bytes(a),
                        Order::Big => <$t>::from_be_bytes(a),
                    }) as f64
                })
                .collect()
        };
    }
    Ok(match ty {
        MI_INT8 => decode!(i8, 1),
        MI_UINT8 => decode!(u8, 1),
        MI_INT16 => decode!(i16, 2),
        MI_UINT16 => decode!(u16, 2),
        MI_INT32 => decode!(i32, 4),
        MI_UINT32 => decode!(u32, 4),
        MI_SINGLE => decode!(f32, 4),
        MI_DOUBLE => decode!(f64, 8),
        MI_INT64 => decode!(i64, 8),
        MI_UINT64 => decode!(u64, 8),
        other => return Err(format!("numeric data of unsupported element type {other}")),
    })
}

/// Parse the contents of one `miMATRIX` element; its numbers are decoded only where `want`
/// holds for its name (the others are listed by name only).
fn matrix(b: &[u8], order: Order, want: &dyn Fn(&str) -> bool) -> Result<Entry, String> {
    let mut c = Cursor { bytes: b, at: 0, order };
    let (_, flags) = c.element()?;
    let flag_word =
        numbers(MI_UINT32, flags.get(..4).ok_or("short array flags")?, order)?[0] as u32;
    let class = flag_word & 0xff;
    let (complex, logical) = (flag_word & 0x0800 != 0, flag_word & 0x0200 != 0);
    let (dty, dims) = c.element()?;
    let dims: Vec<usize> = numbers(dty, dims, order)?.iter().map(|&d| d as usize).collect();
    let (nty, name) = c.element()?;
    if nty != MI_INT8 && nty != MI_UINT8 && nty != MI_UTF8 {
        return Err(format!("array name of element type {nty}; expected text"));
    }
    let name = String::from_utf8_lossy(name).into_owned();
    let numeric = (6..=15).contains(&class);
    if !numeric || complex {
        let what = if complex && numeric {
            format!("a complex {} array", class_name(class))
        } else {
            class_name(class).to_string()
        };
        return Ok(Entry::Other { name, what });
    }
    if !want(&name) {
        return Ok(Entry::Other { name, what: "not asked for".into() });
    }
    let (rty, real) = c.element()?;
    let data = numbers(rty, real, order).map_err(|e| format!("variable '{name}': {e}"))?;
    let count: usize = dims.iter().product();
    if data.len() != count {
        return Err(format!("variable '{name}': {} values for dimensions {:?}", data.len(), dims));
    }
    let _ = logical; // logical arrays are uint8 0/1: read as numbers
    Ok(Entry::Numeric(MatVariable { name, dims, data }))
}

/// One top-level element's variable, from its type and bytes.
fn top_level(
    ty: u32,
    data: &[u8],
    order: Order,
    want: &dyn Fn(&str) -> bool,
) -> Result<Option<Entry>, String> {
    match ty {
        MI_MATRIX => matrix(data, order, want).map(Some),
        MI_COMPRESSED => {
            let mut plain = Vec::new();
            flate2::read::ZlibDecoder::new(data)
                .read_to_end(&mut plain)
                .map_err(|e| format!("a compressed element does not inflate: {e}"))?;
            let mut inner = Cursor { bytes: &plain, at: 0, order };
            let (ity, idata) = inner.element()?;
            if ity == MI_MATRIX { matrix(idata, order, want).map(Some) } else { Ok(None) }
        }
        _ => Ok(None), // other top-level elements carry no variable
    }
}

/// Every variable of the file read by `r` from just after its 128-byte header, `len` bytes
/// long in all. One top-level element is held at a time (its bytes, inflated, and the
/// numbers of a variable `want` asks for), never the whole file.
fn entries(
    r: &mut impl Read,
    len: u64,
    order: Order,
    want: &dyn Fn(&str) -> bool,
) -> Result<Vec<Entry>, String> {
    let mut at: u64 = 128;
    let mut out = Vec::new();
    let word = |b: [u8; 4]| match order {
        Order::Little => u32::from_le_bytes(b),
        Order::Big => u32::from_be_bytes(b),
    };
    let truncated = |n: u64, at: u64| {
        format!("truncated: an element needs {n} bytes at offset {at} but the data ends")
    };
    while at < len {
        let mut tag = [0u8; 8];
        if len - at < 8 {
            return Err(truncated(8, at));
        }
        r.read_exact(&mut tag).map_err(|e| e.to_string())?;
        at += 8;
        let first = word(tag[..4].try_into().expect("4 bytes"));
        if first >> 16 != 0 {
            continue; // a small element (4 bytes of data in the tag) carries no variable
        }
        let n = u64::from(word(tag[4..].try_into().expect("4 bytes")));
        if n > len - at {
            return Err(truncated(n, at));
        }
        let mut data = vec![0u8; n as usize];
        r.read_exact(&mut data).map_err(|e| e.to_string())?;
        at += n;
        if first != MI_COMPRESSED {
            let pad = ((8 - n % 8) % 8).min(len - at);
            std::io::copy(&mut r.by_ref().take(pad), &mut std::io::sink())
                .map_err(|e| e.to_string())?;
            at += pad;
        }
        if let Some(e) = top_level(first, &data, order, want)? {
            out.push(e);
        }
    }
    Ok(out)
}

/// The byte order from the header, after checking it is a MAT v5 file.
fn header_order(bytes: &[u8]) -> Result<Order, String> {
    if bytes.len() < 128 {
        return Err("shorter than a MAT file's 128-byte header; expected a MAT v5 file".into());
    }
    let hdf5 = bytes.starts_with(b"\x89HDF") || bytes.get(512..516) == Some(b"\x89HDF".as_ref());
    if hdf5 || bytes.starts_with(b"MATLAB 7.3") {
        return Err(
            "a MAT v7.3 (HDF5) file; save it with `save(..., '-v7')` for a MAT v5 file".into()
        );
    }
    match &bytes[126..128] {
        b"IM" => Ok(Order::Little),
        b"MI" => Ok(Order::Big),
        _ => Err("no MAT v5 endian mark at bytes 126–127; expected a MATLAB MAT v5 file".into()),
    }
}

/// Read every real numeric variable of a MAT v5 file (compressed or not).
///
/// Errors name the file: not a MAT v5 file (v7.3 HDF5 files are recognised and told so),
/// truncated or corrupt elements.
pub fn read_mat(path: &Path) -> Result<Vec<MatVariable>, IoError> {
    Ok(read_entries(path, &|_| true)?
        .into_iter()
        .filter_map(|e| match e {
            Entry::Numeric(v) => Some(v),
            Entry::Other { .. } => None,
        })
        .collect())
}

/// The file's variables, read element by element ([`entries`]); the numbers of those
/// `want` asks for.
fn read_entries(path: &Path, want: &dyn Fn(&str) -> bool) -> Result<Vec<Entry>, IoError> {
    use std::io::{Seek, SeekFrom};
    let file = std::fs::File::open(path).map_err(|e| IoError::fs(path, e))?;
    let len = file.metadata().map_err(|e| IoError::fs(path, e))?.len();
    let mut r = std::io::BufReader::new(file);
    // The header, and as far as byte 516 for an HDF5 signature after a user block.
    let mut head = Vec::new();
    (&mut r).take(516).read_to_end(&mut head).map_err(|e| IoError::fs(path, e))?;
    let order = header_order(&head).map_err(|m| IoError::format(path, m))?;
    r.seek(SeekFrom::Start(128)).map_err(|e| IoError::fs(path, e))?;
    entries(&mut r, len, order, want).map_err(|m| IoError::format(path, m))
}

/// Read the named variables as vectors of `f64`, in the order asked. Each must be a real
/// numeric vector or scalar (a matrix with more than one non-singleton dimension, a struct,
/// cell, char or complex array is an error naming the variable and what it is); a missing
/// name is an error listing the variables present.
pub fn read_mat_vectors(path: &Path, names: &[&str]) -> Result<Vec<Vec<f64>>, IoError> {
    let mut all = read_entries(path, &|name| names.contains(&name))?;
    let present: Vec<String> = all.iter().map(|e| e.name().to_string()).collect();
    let mut out = Vec::with_capacity(names.len());
    for (j, &name) in names.iter().enumerate() {
        let at = all.iter().position(|e| e.name() == name).ok_or_else(|| {
            IoError::format(
                path,
                format!("missing variable '{name}' (found: {})", present.join(", ")),
            )
        })?;
        match &mut all[at] {
            Entry::Other { what, .. } => {
                return Err(IoError::format(
                    path,
                    format!("variable '{name}' is {what}; expected a real numeric vector"),
                ));
            }
            Entry::Numeric(v) if !v.is_vector() => {
                return Err(IoError::format(
                    path,
                    format!("variable '{name}' is a {} matrix; expected a vector", v.shape()),
                ));
            }
            Entry::Numeric(v) => {
                if let Some(k) = v.data.iter().position(|x| !x.is_finite()) {
                    return Err(IoError::format(
                        path,
                        format!(
                            "variable '{name}', element {}: {} is not a finite number",
                            k + 1,
                            v.data[k]
                        ),
                    ));
                }
                // Moved out, unless the same name is asked for again later.
                let again = names[j + 1..].contains(&name);
                out.push(if again { v.data.clone() } else { std::mem::take(&mut v.data) });
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests;
