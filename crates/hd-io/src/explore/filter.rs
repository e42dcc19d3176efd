//! `--filter` expressions: one comparison each, `COL OP VALUE` with OP one of
//! `== != < <= > >=`, or `COL in [V1, V2, …]`. Values are numbers (`5e5`, `-0.1`), bare
//! words (`full`) or quoted texts (`"ok"`, `'a b'`). Several filters are combined with
//! *and*. Errors name the token that could not be read and its position.

use crate::explore::schema::{ColumnInfo, suggestion};
use crate::explore::token::{LexError, Op, Tok, Token, tokenize};
use polars::prelude::{Expr, col, lit};
use std::fmt;

/// A value on the right of a comparison.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    /// A number.
    Num(f64),
    /// A text (a bare word or a quoted text).
    Text(String),
}

impl fmt::Display for Value {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Value::Num(x) => write!(f, "{x}"),
            Value::Text(s) => write!(f, "\"{s}\""),
        }
    }
}

/// What a filter tests.
#[derive(Clone, Debug, PartialEq)]
pub enum Test {
    /// `COL OP VALUE`.
    Compare(Op, Value),
    /// `COL in [VALUES]`.
    In(Vec<Value>),
}

/// One parsed filter, with the positions of its parts for later errors.
#[derive(Clone, Debug, PartialEq)]
pub struct Filter {
    /// The expression as written.
    pub source: String,
    /// Column name.
    pub column: String,
    /// The test applied to it.
    pub test: Test,
    column_pos: usize,
    /// Position and text of each value token.
    value_tokens: Vec<(usize, String)>,
}

/// A filter that could not be read or does not fit the table.
#[derive(Clone, Debug, PartialEq)]
pub struct FilterError {
    /// The whole expression.
    pub expr: String,
    /// 1-based character position of the token.
    pub position: usize,
    /// The token as written (`end of expression` past the last one).
    pub token: String,
    /// What would have been accepted there.
    pub expected: String,
}

impl std::error::Error for FilterError {}

impl fmt::Display for FilterError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let what = if self.position > self.expr.chars().count() {
            "the end of the expression".to_string()
        } else {
            format!("{:?} at position {}", self.token, self.position)
        };
        write!(f, "--filter '{}': cannot read {what}: expected {}", self.expr, self.expected)?;
        let caret = " ".repeat(self.position.saturating_sub(1));
        write!(f, "\n  {}\n  {caret}^", self.expr)
    }
}

/// A cursor over the tokens of one expression.
struct Parser<'a> {
    src: &'a str,
    tokens: Vec<Token>,
    at: usize,
}

impl Parser<'_> {
    fn peek(&self) -> &Token {
        &self.tokens[self.at.min(self.tokens.len() - 1)]
    }

    fn next(&mut self) -> Token {
        let t = self.peek().clone();
        self.at += 1;
        t
    }

    fn error(&self, t: &Token, expected: impl Into<String>) -> FilterError {
        FilterError {
            expr: self.src.to_string(),
            position: t.pos,
            token: t.text.clone(),
            expected: expected.into(),
        }
    }

    fn value(&mut self) -> Result<(Value, (usize, String)), FilterError> {
        let t = self.next();
        let v = match &t.tok {
            Tok::Word(w) if looks_numeric(w) => match w.parse::<f64>() {
                Ok(x) => Value::Num(x),
                Err(_) => return Err(self.error(&t, "a number such as 5e5 or -0.25")),
            },
            Tok::Word(w) | Tok::Quoted(w) => Value::Text(w.clone()),
            _ => return Err(self.error(&t, "a value: a number, a word or a quoted text")),
        };
        Ok((v, (t.pos, t.text)))
    }
}

/// Whether a bare word is meant as a number (it starts like one).
fn looks_numeric(w: &str) -> bool {
    let mut c = w.chars();
    match c.next() {
        Some(d) if d.is_ascii_digit() || d == '.' => true,
        Some('-' | '+') => c.next().is_some_and(|d| d.is_ascii_digit() || d == '.'),
        _ => false,
    }
}

/// Parse one `--filter` expression.
pub fn parse_filter(src: &str) -> Result<Filter, FilterError> {
    let tokens = tokenize(src).map_err(|(position, token, expected): LexError| FilterError {
        expr: src.to_string(),
        position,
        token,
        expected,
    })?;
    let mut p = Parser { src, tokens, at: 0 };
    let first = p.next();
    let Tok::Word(column) = &first.tok else {
        return Err(p.error(&first, "a column name, e.g. Kbar or status"));
    };
    if looks_numeric(column) {
        return Err(p.error(&first, "a column name first, e.g. `Kbar > 5e5`"));
    }
    let op = p.next();
    let mut value_tokens = Vec::new();
    let test = match &op.tok {
        Tok::Op(o) => {
            let (v, at) = p.value()?;
            value_tokens.push(at);
            Test::Compare(*o, v)
        }
        Tok::Word(w) if w == "in" => {
            let open = p.next();
            if open.tok != Tok::Open {
                return Err(p.error(&open, "'[' to start the list of values"));
            }
            let mut values = Vec::new();
            loop {
                let (v, at) = p.value()?;
                values.push(v);
                value_tokens.push(at);
                let sep = p.next();
                match sep.tok {
                    Tok::Comma => continue,
                    Tok::Close => break,
                    _ => return Err(p.error(&sep, "',' or ']' in the list of values")),
                }
            }
            Test::In(values)
        }
        _ => return Err(p.error(&op, "an operator (== != < <= > >=) or `in [..]`")),
    };
    let end = p.next();
    if end.tok != Tok::End {
        return Err(p.error(
            &end,
            "the end of the expression (one comparison per --filter; repeat --filter to combine)",
        ));
    }
    Ok(Filter {
        source: src.to_string(),
        column: column.clone(),
        test,
        column_pos: first.pos,
        value_tokens,
    })
}

impl Filter {
    fn error_at(&self, position: usize, token: &str, expected: String) -> FilterError {
        FilterError { expr: self.source.clone(), position, token: token.to_string(), expected }
    }

    /// Check the filter against the table's columns and build the polars predicate.
    pub(crate) fn to_expr(&self, columns: &[ColumnInfo]) -> Result<Expr, FilterError> {
        let Some(info) = columns.iter().find(|c| c.name == self.column) else {
            let hint = suggestion(columns, &self.column)
                .map(|s| format!(" (did you mean '{s}'?)"))
                .unwrap_or_default();
            return Err(self.error_at(
                self.column_pos,
                &self.column,
                format!("a column of the table{hint}"),
            ));
        };
        let values: Vec<&Value> = match &self.test {
            Test::Compare(_, v) => vec![v],
            Test::In(vs) => vs.iter().collect(),
        };
        for (v, (pos, text)) in values.iter().zip(&self.value_tokens) {
            match (v, info.numeric) {
                (Value::Text(_), true) => {
                    return Err(self.error_at(
                        *pos,
                        text,
                        format!("a number: column '{}' holds numbers", info.name),
                    ));
                }
                (Value::Num(_), false) => {
                    return Err(self.error_at(
                        *pos,
                        text,
                        format!(
                            "a word or a quoted text: column '{}' holds {} values",
                            info.name, info.dtype
                        ),
                    ));
                }
                _ => {}
            }
        }
        if let (Test::Compare(op, _), false) = (&self.test, info.numeric)
            && !matches!(op, Op::Eq | Op::Ne)
        {
            return Err(self.error_at(
                self.column_pos,
                &self.column,
                format!("a numeric column for '{}' ('{}' holds text)", op.symbol(), info.name),
            ));
        }
        let c = col(self.column.as_str());
        let lit_of = |v: &Value| match v {
            Value::Num(x) => lit(*x),
            Value::Text(s) => lit(s.clone()),
        };
        Ok(match &self.test {
            Test::Compare(op, v) => {
                let v = lit_of(v);
                match op {
                    Op::Eq => c.eq(v),
                    Op::Ne => c.neq(v),
                    Op::Lt => c.lt(v),
                    Op::Le => c.lt_eq(v),
                    Op::Gt => c.gt(v),
                    Op::Ge => c.gt_eq(v),
                }
            }
            Test::In(vs) => vs
                .iter()
                .map(|v| c.clone().eq(lit_of(v)))
                .reduce(|a, b| a.or(b))
                .unwrap_or_else(|| lit(false)),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_the_three_forms() {
        let f = parse_filter(r#"status == "ok""#).unwrap();
        assert_eq!(f.test, Test::Compare(Op::Eq, Value::Text("ok".into())));
        let f = parse_filter("Kbar > 5e5").unwrap();
        assert_eq!(f.test, Test::Compare(Op::Gt, Value::Num(5e5)));
        let f = parse_filter("variant in [full, damped]").unwrap();
        assert_eq!(
            f.test,
            Test::In(vec![Value::Text("full".into()), Value::Text("damped".into())])
        );
    }

    #[test]
    fn errors_name_the_token() {
        let e = parse_filter("Kbar > 5e5 and c < 3").unwrap_err();
        assert_eq!((e.token.as_str(), e.position), ("and", 12));
        let e = parse_filter("Kbar >> 5").unwrap_err();
        assert_eq!((e.token.as_str(), e.position), (">", 7));
        let e = parse_filter("variant in [full damped]").unwrap_err();
        assert_eq!(e.token, "damped");
        let e = parse_filter("Kbar > 1.2.3").unwrap_err();
        assert_eq!(e.token, "1.2.3");
    }
}
