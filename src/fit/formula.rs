//! A small expression language for fits given as text (`kiln verify-fit FILE.toml`): numbers,
//! the variables `mu`, `r` (perceptual roughness) and `alpha = r^2`, names defined earlier in
//! the file, `+ - * / ^` (`^` binds tightest and to the right; unary minus binds looser than
//! `^`, so `-x^2 = -(x^2)`), parentheses and the shader functions `pow exp exp2 log log2 sqrt
//! abs min max clamp saturate mix`. Shading languages' `x * x` and `pow(x, y)` read as written.
//!
//! Every formula is hostile input: its length, nesting and names are checked, and an error
//! names the formula and the character where it went wrong. Evaluation never panics; a value
//! outside a function's domain is NaN, which the audit reports as such.

use crate::error::{escaped, quoted};
use std::fmt;

/// The longest formula accepted, in bytes.
pub const MAX_FORMULA_BYTES: usize = 4096;
/// The deepest nesting of parentheses and operators accepted.
pub const MAX_DEPTH: usize = 64;
/// The most names a file may define.
pub const MAX_DEFINITIONS: usize = 64;

/// A parsed expression over numbered variable slots.
#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    Number(f64),
    /// A slot: 0 `mu`, 1 `r`, 2 `alpha`, then the file's definitions in order.
    Variable(usize),
    Negate(Box<Expr>),
    Binary(Op, Box<Expr>, Box<Expr>),
    Call(Function, Vec<Expr>),
}

/// A binary operator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    Add,
    Subtract,
    Multiply,
    Divide,
    Power,
}

/// The functions a formula may call, with the shading languages' meaning.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Function {
    Pow,
    Exp,
    Exp2,
    Log,
    Log2,
    Sqrt,
    Abs,
    Min,
    Max,
    Clamp,
    Saturate,
    /// `mix(a, b, t) = a + (b - a) t` (GLSL; HLSL's `lerp`, also accepted).
    Mix,
}

impl Function {
    const ALL: [(&'static str, Function, usize); 13] = [
        ("pow", Function::Pow, 2),
        ("exp", Function::Exp, 1),
        ("exp2", Function::Exp2, 1),
        ("log", Function::Log, 1),
        ("log2", Function::Log2, 1),
        ("sqrt", Function::Sqrt, 1),
        ("abs", Function::Abs, 1),
        ("min", Function::Min, 2),
        ("max", Function::Max, 2),
        ("clamp", Function::Clamp, 3),
        ("saturate", Function::Saturate, 1),
        ("mix", Function::Mix, 3),
        ("lerp", Function::Mix, 3),
    ];

    fn named(name: &str) -> Option<(Function, usize)> {
        Self::ALL
            .iter()
            .find(|(n, ..)| *n == name)
            .map(|&(_, f, arity)| (f, arity))
    }

    fn names() -> String {
        Self::ALL
            .iter()
            .map(|(n, ..)| *n)
            .collect::<Vec<_>>()
            .join(", ")
    }

    fn apply(self, a: &[f64]) -> f64 {
        match self {
            Function::Pow => a[0].powf(a[1]),
            Function::Exp => a[0].exp(),
            Function::Exp2 => a[0].exp2(),
            Function::Log => a[0].ln(),
            Function::Log2 => a[0].log2(),
            Function::Sqrt => a[0].sqrt(),
            Function::Abs => a[0].abs(),
            Function::Min => a[0].min(a[1]),
            Function::Max => a[0].max(a[1]),
            // As the shading languages: NaN-free inputs give min(max(x, lo), hi).
            Function::Clamp => a[0].max(a[1]).min(a[2]),
            Function::Saturate => a[0].clamp(0.0, 1.0),
            Function::Mix => a[0] + (a[1] - a[0]) * a[2],
        }
    }
}

/// Where and why a formula failed to parse.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FormulaError {
    /// Where in the formula, in characters from its start (not bytes: "at character N" after
    /// non-ASCII text counted bytes, issue 64).
    pub at: usize,
    pub message: String,
}

impl fmt::Display for FormulaError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "at character {}: {}", self.at + 1, self.message)
    }
}

/// The names of the built-in variable slots, in order.
pub const VARIABLES: [&str; 3] = ["mu", "r", "alpha"];

impl Expr {
    /// Parses `text` where `names` are the variable slots' names (the built-ins, then the
    /// definitions so far).
    ///
    /// # Errors
    /// A formula too long, too deep, with an unknown name or function, a wrong number of
    /// arguments, or bad syntax.
    pub fn parse(text: &str, names: &[String]) -> Result<Expr, FormulaError> {
        Self::parse_bytes(text, names).map_err(|mut e| {
            let mut end = e.at.min(text.len());
            while !text.is_char_boundary(end) {
                end -= 1;
            }
            e.at = text[..end].chars().count();
            e
        })
    }

    /// [`Expr::parse`] with the error's position in bytes.
    fn parse_bytes(text: &str, names: &[String]) -> Result<Expr, FormulaError> {
        if text.len() > MAX_FORMULA_BYTES {
            return Err(FormulaError {
                at: MAX_FORMULA_BYTES,
                message: format!(
                    "the formula is {} bytes long; at most {MAX_FORMULA_BYTES} are read",
                    text.len()
                ),
            });
        }
        let mut parser = Parser {
            text,
            at: 0,
            names,
            depth: 0,
        };
        let expr = parser.expression()?;
        parser.skip_space();
        if parser.at < text.len() {
            return Err(parser.error(format!(
                "unexpected {} after a complete expression",
                quoted(&parser.rest().chars().next().unwrap_or(' ').to_string())
            )));
        }
        Ok(expr)
    }

    /// The value with the variable slots `slots`.
    #[must_use]
    pub fn eval(&self, slots: &[f64]) -> f64 {
        match self {
            Expr::Number(x) => *x,
            Expr::Variable(k) => slots.get(*k).copied().unwrap_or(f64::NAN),
            Expr::Negate(e) => -e.eval(slots),
            Expr::Binary(op, a, b) => {
                let (a, b) = (a.eval(slots), b.eval(slots));
                match op {
                    Op::Add => a + b,
                    Op::Subtract => a - b,
                    Op::Multiply => a * b,
                    Op::Divide => a / b,
                    Op::Power => a.powf(b),
                }
            }
            Expr::Call(f, args) => {
                let values: Vec<f64> = args.iter().map(|e| e.eval(slots)).collect();
                f.apply(&values)
            }
        }
    }
}

struct Parser<'a> {
    text: &'a str,
    at: usize,
    names: &'a [String],
    depth: usize,
}

impl Parser<'_> {
    fn rest(&self) -> &str {
        &self.text[self.at..]
    }

    fn error(&self, message: String) -> FormulaError {
        FormulaError {
            at: self.at,
            message,
        }
    }

    fn skip_space(&mut self) {
        let trimmed = self.rest().trim_start();
        self.at = self.text.len() - trimmed.len();
    }

    fn eat(&mut self, c: char) -> bool {
        self.skip_space();
        if self.rest().starts_with(c) {
            self.at += c.len_utf8();
            true
        } else {
            false
        }
    }

    fn deeper(&mut self) -> Result<(), FormulaError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            Err(self.error(format!("nested deeper than {MAX_DEPTH} levels")))
        } else {
            Ok(())
        }
    }

    /// `term (('+' | '-') term)*`
    fn expression(&mut self) -> Result<Expr, FormulaError> {
        self.deeper()?;
        let mut left = self.term()?;
        loop {
            let op = if self.eat('+') {
                Op::Add
            } else if self.eat('-') {
                Op::Subtract
            } else {
                break;
            };
            left = Expr::Binary(op, Box::new(left), Box::new(self.term()?));
        }
        self.depth -= 1;
        Ok(left)
    }

    /// `unary (('*' | '/') unary)*`
    fn term(&mut self) -> Result<Expr, FormulaError> {
        let mut left = self.unary()?;
        loop {
            let op = if self.eat('*') {
                Op::Multiply
            } else if self.eat('/') {
                Op::Divide
            } else {
                break;
            };
            left = Expr::Binary(op, Box::new(left), Box::new(self.unary()?));
        }
        Ok(left)
    }

    /// `('-' | '+') unary | power`
    fn unary(&mut self) -> Result<Expr, FormulaError> {
        self.deeper()?;
        let expr = if self.eat('-') {
            Expr::Negate(Box::new(self.unary()?))
        } else if self.eat('+') {
            self.unary()?
        } else {
            self.power()?
        };
        self.depth -= 1;
        Ok(expr)
    }

    /// `atom ('^' unary)?`, right-associative.
    fn power(&mut self) -> Result<Expr, FormulaError> {
        let base = self.atom()?;
        if self.eat('^') {
            let exponent = self.unary()?;
            Ok(Expr::Binary(Op::Power, Box::new(base), Box::new(exponent)))
        } else {
            Ok(base)
        }
    }

    fn atom(&mut self) -> Result<Expr, FormulaError> {
        self.skip_space();
        let start = self.at;
        let Some(c) = self.rest().chars().next() else {
            return Err(self.error("the formula ends where a value was expected".into()));
        };
        if c == '(' {
            self.at += 1;
            let inner = self.expression()?;
            if !self.eat(')') {
                return Err(self.error("missing ')'".into()));
            }
            return Ok(inner);
        }
        if c.is_ascii_digit() || c == '.' {
            return self.number(start);
        }
        if c.is_ascii_alphabetic() || c == '_' {
            let len = self
                .rest()
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .unwrap_or(self.rest().len());
            let name = &self.text[start..start + len];
            self.at += len;
            if self.eat('(') {
                return self.call(name, start);
            }
            return match self.names.iter().position(|n| n == name) {
                Some(k) => Ok(Expr::Variable(k)),
                None => Err(FormulaError {
                    at: start,
                    message: format!(
                        "unknown name {}: the variables are {}",
                        quoted(name),
                        self.names.join(", ")
                    ),
                }),
            };
        }
        Err(self.error(format!(
            "unexpected {} where a value was expected",
            quoted(&c.to_string())
        )))
    }

    fn number(&mut self, start: usize) -> Result<Expr, FormulaError> {
        let bytes = self.rest().as_bytes();
        let mut len = 0;
        let digits = |b: &[u8], mut k: usize| {
            while k < b.len() && b[k].is_ascii_digit() {
                k += 1;
            }
            k
        };
        len = digits(bytes, len);
        if len < bytes.len() && bytes[len] == b'.' {
            len = digits(bytes, len + 1);
        }
        if len < bytes.len() && (bytes[len] == b'e' || bytes[len] == b'E') {
            let mut k = len + 1;
            if k < bytes.len() && (bytes[k] == b'+' || bytes[k] == b'-') {
                k += 1;
            }
            let end = digits(bytes, k);
            if end > k {
                len = end;
            }
        }
        let text = &self.text[start..start + len];
        // Shader literals' suffix: 1.0f.
        self.at += len;
        if self.rest().starts_with('f') || self.rest().starts_with('F') {
            self.at += 1;
        }
        match text.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(Expr::Number(x)),
            _ => Err(FormulaError {
                at: start,
                message: format!("{} is not a finite number", quoted(text)),
            }),
        }
    }

    fn call(&mut self, name: &str, start: usize) -> Result<Expr, FormulaError> {
        let Some((function, arity)) = Function::named(name) else {
            return Err(FormulaError {
                at: start,
                message: format!(
                    "unknown function {}: the functions are {}",
                    quoted(name),
                    Function::names()
                ),
            });
        };
        let mut args = Vec::new();
        if !self.eat(')') {
            loop {
                args.push(self.expression()?);
                if self.eat(')') {
                    break;
                }
                if !self.eat(',') {
                    return Err(
                        self.error(format!("expected ',' or ')' in {}(...)", escaped(name)))
                    );
                }
            }
        }
        if args.len() != arity {
            return Err(FormulaError {
                at: start,
                message: format!(
                    "{name} takes {arity} argument{}, got {}",
                    if arity == 1 { "" } else { "s" },
                    args.len()
                ),
            });
        }
        Ok(Expr::Call(function, args))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names() -> Vec<String> {
        VARIABLES.iter().map(ToString::to_string).collect()
    }

    fn eval(text: &str, slots: &[f64]) -> f64 {
        Expr::parse(text, &names()).unwrap().eval(slots)
    }

    /// Precedence and associativity as written in shader code and maths: values worked by hand.
    #[test]
    fn operators_bind_as_in_maths() {
        let s = [0.5, 2.0, 4.0];
        assert_eq!(eval("1 + 2 * 3", &s), 7.0);
        assert_eq!(eval("(1 + 2) * 3", &s), 9.0);
        assert_eq!(eval("8 / 4 / 2", &s), 1.0);
        assert_eq!(eval("10 - 4 - 3", &s), 3.0);
        assert_eq!(eval("2 ^ 3 ^ 2", &s), 512.0);
        assert_eq!(eval("-r ^ 2", &s), -4.0);
        assert_eq!(eval("r ^ -1", &s), 0.5);
        assert_eq!(eval("mu * r + alpha", &s), 5.0);
        assert_eq!(eval("1.5e1 + 2.f - .5", &s), 16.5);
        assert_eq!(
            eval("clamp(3, 0, 1) + saturate(-2) + mix(2, 4, 0.25)", &s),
            3.5
        );
        assert_eq!(eval("min(r, alpha) * max(r, alpha) - pow(2, 3)", &s), 0.0);
        assert_eq!(eval("exp2(3) + log2(8) + sqrt(16) + abs(-1)", &s), 16.0);
        assert!((eval("exp(1) * log(exp(2))", &s) - 2.0 * std::f64::consts::E).abs() < 1e-15);
    }

    /// Each kind of bad formula is refused with where and why.
    #[test]
    fn bad_formulas_say_where_and_why() {
        let err = |t: &str| Expr::parse(t, &names()).unwrap_err();
        assert_eq!(err("1 + ").at, 4);
        assert!(err("1 + nu").message.contains("unknown name 'nu'"));
        assert!(err("1 + nu").message.contains("mu, r, alpha"));
        assert!(
            err("powr(1, 2)")
                .message
                .contains("unknown function 'powr'")
        );
        assert!(
            err("pow(1)")
                .message
                .contains("pow takes 2 arguments, got 1")
        );
        assert!(err("(1 + 2").message.contains("missing ')'"));
        assert!(err("1 2").message.contains("unexpected '2'"));
        assert!(err("1e999").message.contains("not a finite number"));
        assert!(err("1 # 2").message.contains("unexpected '#'"));
        let deep = format!("{}1{}", "(".repeat(100), ")".repeat(100));
        assert!(err(&deep).message.contains("nested deeper than 64"));
        let minus = format!("{}1", "-".repeat(100));
        assert!(err(&minus).message.contains("nested deeper"));
        let long = "1+".repeat(3000) + "1";
        assert!(err(&long).message.contains("at most 4096"));
        assert_eq!(
            err("1 + nu").to_string(),
            "at character 5: unknown name 'nu': the variables are mu, r, alpha"
        );
    }

    /// A function outside its domain gives NaN, never a panic; a missing slot is NaN too.
    #[test]
    fn evaluation_never_panics() {
        assert!(eval("sqrt(-1)", &[0.0; 3]).is_nan());
        assert!(eval("log(0) - log(0)", &[0.0; 3]).is_nan());
        assert!(Expr::Variable(7).eval(&[0.0; 3]).is_nan());
    }
}
