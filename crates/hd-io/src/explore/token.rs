//! The tokenizer of `--filter` expressions: words (column names, bare values, numbers),
//! quoted texts, comparison operators, brackets and commas, each with its position.

/// A comparison operator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    /// `==`
    Eq,
    /// `!=`
    Ne,
    /// `<`
    Lt,
    /// `<=`
    Le,
    /// `>`
    Gt,
    /// `>=`
    Ge,
}

impl Op {
    /// The operator as written.
    pub fn symbol(self) -> &'static str {
        match self {
            Op::Eq => "==",
            Op::Ne => "!=",
            Op::Lt => "<",
            Op::Le => "<=",
            Op::Gt => ">",
            Op::Ge => ">=",
        }
    }
}

/// What a token is.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Tok {
    /// A bare word: a column name, a number or an unquoted text value.
    Word(String),
    /// A quoted text (quotes removed).
    Quoted(String),
    /// A comparison operator.
    Op(Op),
    /// `[`
    Open,
    /// `]`
    Close,
    /// `,`
    Comma,
    /// The end of the expression.
    End,
}

/// A token with its 1-based character position and its text as written.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Token {
    pub tok: Tok,
    pub pos: usize,
    pub text: String,
}

/// A token that could not be read: position, text, what was expected.
pub(crate) type LexError = (usize, String, String);

/// Characters that end a bare word.
fn is_special(c: char) -> bool {
    c.is_whitespace() || "[],\"'=!<>".contains(c)
}

/// Split `src` into tokens, ending with [`Tok::End`].
pub(crate) fn tokenize(src: &str) -> Result<Vec<Token>, LexError> {
    let chars: Vec<char> = src.chars().collect();
    let mut out = Vec::new();
    let mut k = 0;
    while k < chars.len() {
        let c = chars[k];
        let pos = k + 1;
        let next = chars.get(k + 1).copied();
        let (tok, len) = match c {
            _ if c.is_whitespace() => {
                k += 1;
                continue;
            }
            '[' => (Tok::Open, 1),
            ']' => (Tok::Close, 1),
            ',' => (Tok::Comma, 1),
            '=' if next == Some('=') => (Tok::Op(Op::Eq), 2),
            '!' if next == Some('=') => (Tok::Op(Op::Ne), 2),
            '<' if next == Some('=') => (Tok::Op(Op::Le), 2),
            '>' if next == Some('=') => (Tok::Op(Op::Ge), 2),
            '<' => (Tok::Op(Op::Lt), 1),
            '>' => (Tok::Op(Op::Gt), 1),
            '=' => return Err((pos, "=".into(), "an operator; did you mean '=='?".into())),
            '!' => return Err((pos, "!".into(), "an operator; did you mean '!='?".into())),
            '"' | '\'' => {
                let Some(end) = chars[k + 1..].iter().position(|&q| q == c) else {
                    let rest: String = chars[k..].iter().collect();
                    return Err((pos, rest, format!("a closing {c} for this quoted text")));
                };
                let text: String = chars[k + 1..k + 1 + end].iter().collect();
                (Tok::Quoted(text), end + 2)
            }
            _ => {
                let len = chars[k..].iter().take_while(|&&w| !is_special(w)).count();
                (Tok::Word(chars[k..k + len].iter().collect()), len)
            }
        };
        out.push(Token { tok, pos, text: chars[k..k + len].iter().collect() });
        k += len;
    }
    out.push(Token { tok: Tok::End, pos: chars.len() + 1, text: "end of expression".into() });
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splits_words_operators_and_lists() {
        let t = tokenize("Kbar>=5e5").unwrap();
        assert_eq!(t[0].tok, Tok::Word("Kbar".into()));
        assert_eq!((t[1].tok.clone(), t[1].pos), (Tok::Op(Op::Ge), 5));
        assert_eq!(t[2].tok, Tok::Word("5e5".into()));
        let t = tokenize(r#"variant in [full, "damped"]"#).unwrap();
        let kinds: Vec<Tok> = t.into_iter().map(|t| t.tok).collect();
        assert_eq!(kinds[2], Tok::Open);
        assert_eq!(kinds[5], Tok::Quoted("damped".into()));
        assert_eq!(kinds[7], Tok::End);
    }

    #[test]
    fn single_equals_and_open_quotes_are_errors() {
        assert_eq!(tokenize("a = 1").unwrap_err().0, 3);
        assert_eq!(tokenize("s == \"ok").unwrap_err().1, "\"ok");
    }
}
