//! Reading the runnable examples out of Markdown and `--help` text.
//!
//! In the docs, a fenced block is runnable when its info string starts with `sh`:
//! - ```` ```sh ````: every command runs and must succeed;
//! - ```` ```sh skip=REASON ````: not run (a cluster, the network, a peer's toolchain); the
//!   test counts it and prints the reason;
//! - ```` ```text ```` whose first line starts with `$ `: a transcript. The command after `$ `
//!   runs, and every line shown under it must appear, in order, in what it printed (stdout
//!   then stderr), so figures quoted in the docs are the ones the command prints. A line `...`
//!   stands for any output. An expected line starting with `error:` means the command must fail.

/// One example command, where it was written, and what it must print.
#[derive(Clone, Debug)]
pub struct Example {
    /// `file:line` of the command.
    pub place: String,
    /// The command as a shell line (continuations joined, comments dropped).
    pub command: String,
    /// `Some(reason)` when it is documented but not run here.
    pub skip: Option<String>,
    /// Lines the output must contain, in order (transcripts only).
    pub expect: Vec<String>,
}

/// Drop a shell comment (`#` at the start of a word, outside quotes) from `line`.
pub fn strip_comment(line: &str) -> String {
    let (mut single, mut double) = (false, false);
    let mut prev = ' ';
    for (k, c) in line.char_indices() {
        match c {
            '\'' if !double => single = !single,
            '"' if !single => double = !double,
            '#' if !single && !double && prev.is_whitespace() => {
                return line[..k].trim_end().to_string();
            }
            _ => {}
        }
        prev = c;
    }
    if line.starts_with('#') { String::new() } else { line.trim_end().to_string() }
}

/// Shell lines of a block body: comments dropped, `\` continuations joined; `(line, text)`
/// with the 0-based line of the command's start within the body.
pub fn commands(body: &[&str]) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut current: Option<(usize, String)> = None;
    let mut k = 0;
    while k < body.len() {
        let raw = body[k];
        // A here-document: the command and its lines, verbatim, up to the terminator.
        if current.is_none()
            && let Some(end) = heredoc_end(raw)
        {
            let mut text = raw.trim().to_string();
            let start = k;
            while k + 1 < body.len() {
                k += 1;
                text.push('\n');
                text.push_str(body[k]);
                if body[k].trim() == end {
                    break;
                }
            }
            out.push((start, text));
            k += 1;
            continue;
        }
        k += 1;
        let line = strip_comment(raw.trim_start_matches(' '));
        let line = line.trim();
        let (text, more) = match line.strip_suffix('\\') {
            Some(t) => (t.trim_end(), true),
            None => (line, false),
        };
        match current.as_mut() {
            Some((_, c)) => {
                c.push(' ');
                c.push_str(text);
            }
            None if !text.is_empty() => current = Some((k - 1, text.to_string())),
            None => {}
        }
        if !more && let Some(done) = current.take() {
            out.push(done);
        }
    }
    out.extend(current);
    out
}

/// The terminator of a here-document the line opens (`cat > f <<'EOF'` → `EOF`).
fn heredoc_end(line: &str) -> Option<String> {
    let (_, rest) = line.split_once("<<")?;
    let word = rest.trim_start_matches('-').trim();
    let word = word.split_whitespace().next()?.trim_matches(|c| c == '\'' || c == '"');
    (!word.is_empty() && word.chars().all(|c| c.is_ascii_alphanumeric() || c == '_'))
        .then(|| word.to_string())
}

/// The runnable examples of one Markdown file, in order. `name` is the file as shown in
/// messages. Fails on a block that holds `hdw` commands but is fenced so it would not run.
pub fn markdown(name: &str, text: &str) -> Result<Vec<Example>, String> {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    let mut k = 0;
    while k < lines.len() {
        let Some(info) = lines[k].trim_start().strip_prefix("```") else {
            k += 1;
            continue;
        };
        let info = info.trim().to_string();
        let start = k + 1;
        let mut end = start;
        while end < lines.len() && !lines[end].trim_start().starts_with("```") {
            end += 1;
        }
        // A block inside a list item is indented as its fence is; the body loses that indent.
        let indent = lines[k].len() - lines[k].trim_start().len();
        let body: Vec<&str> = lines[start..end.min(lines.len())]
            .iter()
            .map(|l| {
                let lead = l.len() - l.trim_start_matches(' ').len();
                &l[lead.min(indent)..]
            })
            .collect();
        let body = &body[..];
        let place = |j: usize| format!("{name}:{}", start + j + 1);
        let lang = info.split_whitespace().next().unwrap_or("");
        if lang == "sh" {
            let skip = info.split_once("skip=").map(|(_, r)| r.trim().replace('-', " "));
            for (j, command) in commands(body) {
                out.push(Example { place: place(j), command, skip: skip.clone(), expect: vec![] });
            }
        } else if let Some(file) = named_file(lang, body) {
            // A file the examples use, written where they run (`# demo.toml` on its first line).
            let command = format!("cat > {file} <<'HDW_DOC_EOF'\n{}\nHDW_DOC_EOF", body.join("\n"));
            out.push(Example { place: place(0), command, skip: None, expect: vec![] });
        } else if lang == "text" && body.first().is_some_and(|l| l.starts_with("$ ")) {
            out.extend(transcript(body, &place));
        } else if (lang.is_empty() || lang == "console" || lang == "bash")
            && let Some(j) = body.iter().position(|l| l.trim_start().starts_with("hdw "))
        {
            return Err(format!(
                "{}: an hdw command in a block fenced ```{lang}: fence it as ```sh (run by \
                 this test) or ```sh skip=REASON",
                place(j)
            ));
        }
        k = end + 1;
    }
    Ok(out)
}

/// The file name of a TOML block that names itself on its first line (`# demo.toml`).
fn named_file(lang: &str, body: &[&str]) -> Option<String> {
    let name = body.first()?.strip_prefix("# ")?.trim();
    let plain = name.chars().all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c));
    (lang == "toml" && plain && name.ends_with(".toml")).then(|| name.to_string())
}

/// The commands of a transcript block and the lines each must print.
fn transcript(body: &[&str], place: &dyn Fn(usize) -> String) -> Vec<Example> {
    let mut out: Vec<Example> = Vec::new();
    let mut j = 0;
    while j < body.len() {
        let Some(first) = body[j].strip_prefix("$ ") else {
            j += 1;
            continue;
        };
        let at = j;
        let mut parts = vec![first];
        while parts.last().is_some_and(|p| p.trim_end().ends_with('\\')) && j + 1 < body.len() {
            j += 1;
            parts.push(body[j]);
        }
        let command = commands(&parts).into_iter().map(|(_, c)| c).collect::<Vec<_>>().join("; ");
        j += 1;
        let mut expect = Vec::new();
        while j < body.len() && !body[j].starts_with("$ ") {
            let line = body[j].trim_end();
            if !line.is_empty() {
                expect.push(line.to_string());
            }
            j += 1;
        }
        out.push(Example { place: place(at), command, skip: None, expect });
    }
    out
}

/// The worked examples at the end of a `--help` text: the lines under `Example:` or
/// `Examples:` that start with `hdw`, continuations joined, trailing notes in parentheses
/// and `#` comments dropped.
pub fn help_examples(name: &str, help: &str) -> Vec<Example> {
    let lines: Vec<&str> = help.lines().collect();
    let Some(from) = lines.iter().position(|l| {
        let t = l.trim();
        t == "Example:" || t == "Examples:" || t.starts_with("Example") && t.ends_with(':')
    }) else {
        return Vec::new();
    };
    let mut body: Vec<String> = Vec::new();
    let mut k = from + 1;
    while k < lines.len() {
        let line = lines[k].trim();
        if line.starts_with("hdw ") {
            let mut cmd = String::new();
            let mut cur = line.to_string();
            loop {
                let (text, more) = match cur.strip_suffix('\\') {
                    Some(t) => (t.trim_end().to_string(), true),
                    None => (cur.clone(), false),
                };
                cmd.push_str(&text);
                if !more || k + 1 >= lines.len() {
                    break;
                }
                cmd.push(' ');
                k += 1;
                cur = lines[k].trim().to_string();
            }
            body.push(drop_note(&cmd));
        }
        k += 1;
    }
    body.into_iter()
        .map(|c| Example {
            place: format!("hdw {name} --help"),
            command: strip_comment(&c),
            skip: None,
            expect: vec![],
        })
        .collect()
}

/// Drop a note written after the command: three or more spaces, then `(`…`)` or `#`.
fn drop_note(cmd: &str) -> String {
    for marker in ["   (", "   #", "  # "] {
        if let Some(k) = cmd.find(marker) {
            return cmd[..k].trim_end().to_string();
        }
    }
    cmd.trim_end().to_string()
}

#[test]
fn shell_lines_join_continuations_and_drop_comments() {
    let body = [
        "# a comment line",
        "hdw study a.toml --out out/a   # trailing note",
        "hdw fit x --columns 'Time [s],F # not a comment' \\",
        "    --out out/f",
        "",
    ];
    let c = commands(&body);
    assert_eq!(c.len(), 2, "{c:?}");
    assert_eq!(c[0], (1, "hdw study a.toml --out out/a".to_string()));
    assert_eq!(c[1].1, "hdw fit x --columns 'Time [s],F # not a comment' --out out/f");
    let doc = ["cat > a.toml <<'EOF'", "x = 1", "# kept", "EOF", "hdw run a.toml"];
    let c = commands(&doc);
    assert_eq!(c.len(), 2, "{c:?}");
    assert_eq!(c[0].1, "cat > a.toml <<'EOF'\nx = 1\n# kept\nEOF");
    assert_eq!(c[1], (4, "hdw run a.toml".to_string()));
}

#[test]
fn transcripts_and_unfenced_commands() {
    let md = "```text\n$ hdw explore out/x \\\n  --pivot a,b\nrows: 3\n...\n```\n";
    let ex = markdown("f.md", md).unwrap();
    assert_eq!(ex.len(), 1);
    assert_eq!(ex[0].command, "hdw explore out/x --pivot a,b");
    assert_eq!(ex[0].expect, ["rows: 3", "..."]);
    let bad = markdown("f.md", "```\nhdw simulate --out x\n```\n").unwrap_err();
    assert!(bad.contains("f.md:2"), "{bad}");
    let skipped = markdown("f.md", "```sh skip=needs-a-cluster\nsqueue -u me\n```\n").unwrap();
    assert_eq!(skipped[0].skip.as_deref(), Some("needs a cluster"));
    let file = markdown("f.md", "```toml\n# demo.toml\nname = \"x\"\n```\n").unwrap();
    assert!(file[0].command.starts_with("cat > demo.toml <<"), "{}", file[0].command);
    let help = "Usage: hdw x\n\nExample:\n  hdw simulate --params a.toml --out o   (the note)\n  hdw a \\\n      --b 1\n";
    let h = help_examples("x", help);
    assert_eq!(h.len(), 2);
    assert_eq!(h[0].command, "hdw simulate --params a.toml --out o");
    assert_eq!(h[1].command, "hdw a --b 1");
}
