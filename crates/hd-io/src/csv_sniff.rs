//! The dialect of a delimited text file as rigs write them: the separator (comma, tab or
//! semicolon) guessed from the header line, `#` comment lines, an optional UTF-8 byte-order
//! mark, CRLF line ends, and fields optionally quoted with `"` (a doubled `""` inside
//! quotes is one quote).

use std::borrow::Cow;

/// The separators recognised, in the order preferred when two are equally likely.
pub const SEPARATORS: [u8; 3] = [b'\t', b';', b','];

/// The prefix of a comment line (skipped wherever it appears).
pub const COMMENT_PREFIX: char = '#';

/// The UTF-8 byte-order mark some spreadsheet exports put at the start of the file.
const BOM: char = '\u{feff}';

/// Decode one raw line: the trailing `\n` / `\r\n` removed, UTF-8 when valid, otherwise
/// Latin-1 (every byte one character), so an instrument's `°C` or `µN` in an unused column
/// or a comment never stops the read.
pub fn decode_line(raw: &[u8]) -> Cow<'_, str> {
    let mut end = raw.len();
    while end > 0 && (raw[end - 1] == b'\n' || raw[end - 1] == b'\r') {
        end -= 1;
    }
    let raw = &raw[..end];
    match std::str::from_utf8(raw) {
        Ok(s) => Cow::Borrowed(s),
        Err(_) => Cow::Owned(raw.iter().map(|&b| b as char).collect()),
    }
}

/// Remove a leading byte-order mark.
pub fn strip_bom(line: &str) -> &str {
    line.strip_prefix(BOM).unwrap_or(line)
}

/// Whether a line carries nothing: empty, blank, or a `#` comment.
pub fn is_skipped(line: &str) -> bool {
    let s = strip_bom(line).trim_start();
    s.is_empty() || s.starts_with(COMMENT_PREFIX)
}

/// How often each separator of [`SEPARATORS`] occurs in `line` outside `"` quotes.
fn counts_outside_quotes(line: &str) -> [usize; 3] {
    let mut counts = [0; 3];
    let mut quoted = false;
    for b in line.bytes() {
        if b == b'"' {
            quoted = !quoted;
        } else if !quoted && let Some(k) = SEPARATORS.iter().position(|&s| s == b) {
            counts[k] += 1;
        }
    }
    counts
}

/// Guess the separator from the header line: the most frequent of tab, semicolon and comma
/// outside quotes. A tie is settled by the first data line (when given): a separator that
/// splits it into as many fields as the header is preferred; then tab before semicolon
/// before comma. A header with none of them is one column; comma is returned.
pub fn sniff_separator(header: &str, first_data: Option<&str>) -> u8 {
    let head = counts_outside_quotes(header);
    let best = head.iter().copied().max().unwrap_or(0);
    if best == 0 {
        return b',';
    }
    let tied: Vec<usize> = (0..SEPARATORS.len()).filter(|&k| head[k] == best).collect();
    if tied.len() > 1
        && let Some(data) = first_data
    {
        let data = counts_outside_quotes(data);
        if let Some(&k) = tied.iter().find(|&&k| data[k] == head[k]) {
            return SEPARATORS[k];
        }
    }
    SEPARATORS[tied[0]]
}

/// A field that could not be split off a line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnclosedQuote {
    /// 0-based index of the field whose quote is not closed on the line.
    pub field: usize,
}

/// Split a line into fields at `sep`. Fields are returned as written (not trimmed), except
/// that a quoted field loses its quotes and its doubled quotes become single. A quoted field
/// must close on the same line. The fast path (no quote on the line) borrows every field.
pub fn split_fields<'a>(
    line: &'a str,
    sep: u8,
    out: &mut Vec<Cow<'a, str>>,
) -> Result<(), UnclosedQuote> {
    out.clear();
    if !line.contains('"') {
        out.extend(line.split(sep as char).map(Cow::Borrowed));
        return Ok(());
    }
    // Quote-aware split, byte by byte (the separator and quote are ASCII, so slicing at
    // their positions keeps UTF-8 boundaries).
    let bytes = line.as_bytes();
    let mut start = 0;
    let mut i = 0;
    loop {
        // Leading blanks before an opening quote are allowed (`a, "b c"`).
        let mut j = i;
        while j < bytes.len() && (bytes[j] == b' ' || bytes[j] == b'\t') && bytes[j] != sep {
            j += 1;
        }
        if j < bytes.len() && bytes[j] == b'"' {
            let mut text = String::new();
            let mut k = j + 1;
            let mut closed = false;
            let mut piece = k;
            while k < bytes.len() {
                if bytes[k] == b'"' {
                    text.push_str(&line[piece..k]);
                    if k + 1 < bytes.len() && bytes[k + 1] == b'"' {
                        text.push('"');
                        k += 2;
                        piece = k;
                        continue;
                    }
                    closed = true;
                    k += 1;
                    break;
                }
                k += 1;
            }
            if !closed {
                return Err(UnclosedQuote { field: out.len() });
            }
            // Anything after the closing quote up to the separator is kept (normally blanks).
            let next = line[k..].find(sep as char).map_or(bytes.len(), |p| k + p);
            text.push_str(&line[k..next]);
            out.push(Cow::Owned(text));
            if next >= bytes.len() {
                return Ok(());
            }
            i = next + 1;
            start = i;
        } else {
            let next = line[start..].find(sep as char).map_or(bytes.len(), |p| start + p);
            out.push(Cow::Borrowed(&line[start..next]));
            if next >= bytes.len() {
                return Ok(());
            }
            i = next + 1;
            start = i;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn split(line: &str, sep: u8) -> Vec<String> {
        let mut v = Vec::new();
        split_fields(line, sep, &mut v).unwrap();
        v.into_iter().map(|c| c.into_owned()).collect()
    }

    #[test]
    fn sniffs_the_most_frequent_separator_outside_quotes() {
        assert_eq!(sniff_separator("Time [s]\tNormal [uN]\tPosition [mm]", None), b'\t');
        assert_eq!(sniff_separator("t;u;\"a,b,c\"", None), b';');
        assert_eq!(sniff_separator("t,u,v", None), b',');
        assert_eq!(sniff_separator("single", None), b',');
        // One comma and one semicolon in the header: the data line decides.
        assert_eq!(sniff_separator("a;b, c", Some("1,5;2")), b';');
        assert_eq!(sniff_separator("a;b, c", Some("1;5,2")), b';');
        assert_eq!(sniff_separator("a;b, c", Some("1,5,2")), b';'); // neither fits: preference
        assert_eq!(sniff_separator("a;b, c", Some("1,2")), b',');
    }

    #[test]
    fn splits_quoted_fields() {
        assert_eq!(split("1,2,3", b','), ["1", "2", "3"]);
        assert_eq!(split("\"a, b\",2,\"say \"\"hi\"\"\"", b','), ["a, b", "2", "say \"hi\""]);
        assert_eq!(split("x, \"y\" ,z", b','), ["x", "y ", "z"]);
        assert_eq!(split("1,,", b','), ["1", "", ""]);
        let mut v = Vec::new();
        assert_eq!(split_fields("a,\"b", b',', &mut v), Err(UnclosedQuote { field: 1 }));
    }

    #[test]
    fn decodes_crlf_and_latin1() {
        assert_eq!(decode_line(b"a,b\r\n"), "a,b");
        assert_eq!(decode_line(b"T [\xb0C]\n"), "T [°C]");
        assert_eq!(strip_bom("\u{feff}t,u"), "t,u");
        assert!(is_skipped("  # comment"));
        assert!(is_skipped("\u{feff}# comment"));
        assert!(is_skipped("   "));
        assert!(!is_skipped("1,2"));
    }
}
