//! Literals (as written in tags.csv, ladder operands and stimulus files) and
//! typed values.

use crate::Invalid;
use crate::types::DataType;
use std::fmt;

/// A literal as written, before it meets a type.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Literal {
    Bool(bool),
    Int(i64),
    Real(f64),
    /// Milliseconds.
    Time(i64),
}

impl Literal {
    /// Parses `true`, `false`, decimal or based integers (`16#FF`, `-2#101`,
    /// `1_000`), reals (`1.5`, `-2.0e3`, `3e2`) and durations (`T#1m30s`,
    /// `TIME#250ms`). Returns a message saying what was expected on failure.
    pub fn parse(text: &str) -> Result<Literal, Invalid> {
        Self::parse_text(text).map_err(Invalid::Literal)
    }

    fn parse_text(text: &str) -> Result<Literal, String> {
        let s = text.trim();
        if s.eq_ignore_ascii_case("true") {
            return Ok(Literal::Bool(true));
        }
        if s.eq_ignore_ascii_case("false") {
            return Ok(Literal::Bool(false));
        }
        let upper = s.to_ascii_uppercase();
        if let Some(rest) = upper.strip_prefix("T#").or_else(|| upper.strip_prefix("TIME#")) {
            return parse_duration(rest)
                .map(Literal::Time)
                .map_err(|()| format!("`{s}` is not a duration; write it like T#1m30s or T#250ms"));
        }
        let (neg, body) = match s.as_bytes().first() {
            Some(b'-') => (true, &s[1..]),
            Some(b'+') => (false, &s[1..]),
            _ => (false, s),
        };
        if body.is_empty() {
            return Err(format!("`{s}` is not a number"));
        }
        if let Some((base, digits)) = body.split_once('#') {
            let radix = match base {
                "16" => 16,
                "8" => 8,
                "2" => 2,
                "10" => 10,
                _ => {
                    return Err(format!("`{s}`: the base of a based literal is 2, 8, 10 or 16"));
                }
            };
            let digits = digits.replace('_', "");
            let v =
                u64::from_str_radix(&digits, radix).map_err(|_| format!("`{s}` is not a valid base-{radix} number"))?;
            let v = i128::from(v);
            let v = if neg { -v } else { v };
            return i64::try_from(v)
                .map(Literal::Int)
                .map_err(|_| format!("`{s}` does not fit in 64 bits"));
        }
        let clean = body.replace('_', "");
        if !clean.bytes().next().is_some_and(|b| b.is_ascii_digit())
            || !clean
                .bytes()
                .all(|b| b.is_ascii_digit() || matches!(b, b'.' | b'e' | b'E' | b'+' | b'-'))
        {
            return Err(format!("`{s}` is not a number"));
        }
        if clean.bytes().all(|b| b.is_ascii_digit()) {
            let v: i128 = clean.parse().map_err(|_| format!("`{s}` is too large"))?;
            let v = if neg { -v } else { v };
            return i64::try_from(v)
                .map(Literal::Int)
                .map_err(|_| format!("`{s}` does not fit in 64 bits"));
        }
        if clean.ends_with('.') || clean.contains(".e") || clean.contains(".E") {
            return Err(format!("`{s}`: write a digit after the decimal point"));
        }
        let v: f64 = clean.parse().map_err(|_| format!("`{s}` is not a number"))?;
        if !v.is_finite() {
            return Err(format!("`{s}` is too large"));
        }
        Ok(Literal::Real(if neg { -v } else { v }))
    }
}

/// `1h2m3s4ms` style durations (d, h, m, s, ms; integers; optional `_`),
/// upper case.
fn parse_duration(s: &str) -> Result<i64, ()> {
    let (neg, mut rest) = match s.strip_prefix('-') {
        Some(r) => (true, r),
        None => (false, s),
    };
    if rest.is_empty() {
        return Err(());
    }
    let mut total: i128 = 0;
    while !rest.is_empty() {
        rest = rest.trim_start_matches('_');
        let digits = rest.bytes().take_while(|b| b.is_ascii_digit()).count();
        if digits == 0 {
            return Err(());
        }
        let n: i128 = rest[..digits].parse().map_err(|_| ())?;
        rest = &rest[digits..];
        let unit_len = rest.bytes().take_while(|b| b.is_ascii_alphabetic()).count();
        let factor = match &rest[..unit_len] {
            "D" => 86_400_000,
            "H" => 3_600_000,
            "M" => 60_000,
            "S" => 1_000,
            "MS" => 1,
            _ => return Err(()),
        };
        rest = &rest[unit_len..];
        total = n
            .checked_mul(factor)
            .and_then(|v| v.checked_add(total))
            .filter(|&v| v <= i64::MAX as i128)
            .ok_or(())?;
    }
    let total = total as i64;
    Ok(if neg { -total } else { total })
}

/// A value of an elementary type.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Value {
    Bool(bool),
    Sint(i8),
    Int(i16),
    Dint(i32),
    Lint(i64),
    Real(f32),
    Lreal(f64),
    /// Milliseconds.
    Time(i32),
}

impl Value {
    /// The zero of an elementary type (`None` for structures).
    pub fn zero(ty: DataType) -> Option<Value> {
        Some(match ty {
            DataType::Bool => Value::Bool(false),
            DataType::Sint => Value::Sint(0),
            DataType::Int => Value::Int(0),
            DataType::Dint => Value::Dint(0),
            DataType::Lint => Value::Lint(0),
            DataType::Real => Value::Real(0.0),
            DataType::Lreal => Value::Lreal(0.0),
            DataType::Time => Value::Time(0),
            DataType::Timer | DataType::Counter | DataType::Pid => return None,
        })
    }

    pub fn data_type(&self) -> DataType {
        match self {
            Value::Bool(_) => DataType::Bool,
            Value::Sint(_) => DataType::Sint,
            Value::Int(_) => DataType::Int,
            Value::Dint(_) => DataType::Dint,
            Value::Lint(_) => DataType::Lint,
            Value::Real(_) => DataType::Real,
            Value::Lreal(_) => DataType::Lreal,
            Value::Time(_) => DataType::Time,
        }
    }

    /// Converts a literal to a value of `ty`, refusing what does not fit
    /// (a real into an integer, 40000 into an INT, 2 into a BOOL).
    pub fn from_literal(lit: Literal, ty: DataType) -> Result<Value, Invalid> {
        Self::from_literal_text(lit, ty).map_err(Invalid::Value)
    }

    fn from_literal_text(lit: Literal, ty: DataType) -> Result<Value, String> {
        let int = |v: i64| -> Result<Value, String> {
            let (lo, hi) = ty.int_range().ok_or_else(|| format!("{ty} does not take an integer"))?;
            if v < lo || v > hi {
                return Err(format!("{v} is out of range for {ty} ({lo} to {hi})"));
            }
            Ok(match ty {
                DataType::Sint => Value::Sint(v as i8),
                DataType::Int => Value::Int(v as i16),
                DataType::Dint => Value::Dint(v as i32),
                DataType::Time => Value::Time(v as i32),
                _ => Value::Lint(v),
            })
        };
        match (lit, ty) {
            (Literal::Bool(b), DataType::Bool) => Ok(Value::Bool(b)),
            (Literal::Int(0), DataType::Bool) => Ok(Value::Bool(false)),
            (Literal::Int(1), DataType::Bool) => Ok(Value::Bool(true)),
            (_, DataType::Bool) => Err("BOOL takes 0, 1, true or false".into()),
            (Literal::Int(v), t) if t.is_integer() => int(v),
            (Literal::Time(v), t) if t.is_integer() => int(v),
            (Literal::Int(v), DataType::Real) => Ok(Value::Real(v as f32)),
            (Literal::Int(v), DataType::Lreal) => Ok(Value::Lreal(v as f64)),
            (Literal::Real(v), DataType::Real) => {
                if v.abs() > f32::MAX as f64 {
                    Err(format!("{v} is out of range for REAL"))
                } else {
                    Ok(Value::Real(v as f32))
                }
            }
            (Literal::Real(v), DataType::Lreal) => Ok(Value::Lreal(v)),
            (Literal::Real(_), t) if t.is_integer() => Err(format!("{t} takes an integer, not a real")),
            (Literal::Bool(_), t) => Err(format!("{t} takes a number, not a boolean")),
            (Literal::Time(_), t) => Err(format!("{t} does not take a duration")),
            (_, t) => Err(format!("{t} is a structure and takes no single value")),
        }
    }

    /// Parses text as a value of `ty`.
    pub fn parse(text: &str, ty: DataType) -> Result<Value, Invalid> {
        Value::from_literal(Literal::parse(text)?, ty)
    }

    pub fn as_bool(&self) -> bool {
        match *self {
            Value::Bool(b) => b,
            Value::Real(r) => r != 0.0,
            Value::Lreal(r) => r != 0.0,
            _ => self.as_i64() != 0,
        }
    }

    /// Integer view (reals truncate toward zero).
    pub fn as_i64(&self) -> i64 {
        match *self {
            Value::Bool(b) => b as i64,
            Value::Sint(v) => v as i64,
            Value::Int(v) => v as i64,
            Value::Dint(v) | Value::Time(v) => v as i64,
            Value::Lint(v) => v,
            Value::Real(v) => v as i64,
            Value::Lreal(v) => v as i64,
        }
    }

    pub fn as_f64(&self) -> f64 {
        match *self {
            Value::Real(v) => v as f64,
            Value::Lreal(v) => v,
            _ => self.as_i64() as f64,
        }
    }
}

/// Booleans as 0/1, integers in decimal, reals in the shortest form that
/// reads back exactly (SPEC §10.2).
impl fmt::Display for Value {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Value::Bool(b) => write!(f, "{}", *b as u8),
            Value::Sint(v) => write!(f, "{v}"),
            Value::Int(v) => write!(f, "{v}"),
            Value::Dint(v) | Value::Time(v) => write!(f, "{v}"),
            Value::Lint(v) => write!(f, "{v}"),
            Value::Real(v) if exponent_form(*v as f64) => write!(f, "{v:e}"),
            Value::Lreal(v) if exponent_form(*v) => write!(f, "{v:e}"),
            Value::Real(v) => write!(f, "{v}"),
            Value::Lreal(v) => write!(f, "{v}"),
        }
    }
}

/// Reals print with the fewest digits that read back exactly; like Python's
/// `repr`, in exponent form outside 1e-4 ≤ |v| < 1e16 (so REAL max is
/// `3.4028235e38`, not 39 digits).
fn exponent_form(v: f64) -> bool {
    let a = v.abs();
    a != 0.0 && !(1e-4..1e16).contains(&a)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn literals_of_every_form_parse() {
        assert_eq!(Literal::parse("42"), Ok(Literal::Int(42)));
        assert_eq!(Literal::parse("-1_000"), Ok(Literal::Int(-1000)));
        assert_eq!(Literal::parse("16#FF"), Ok(Literal::Int(255)));
        assert_eq!(Literal::parse("2#1010"), Ok(Literal::Int(10)));
        assert_eq!(Literal::parse("1.5"), Ok(Literal::Real(1.5)));
        assert_eq!(Literal::parse("-2.5e2"), Ok(Literal::Real(-250.0)));
        assert_eq!(Literal::parse("3e2"), Ok(Literal::Real(300.0)));
        assert_eq!(Literal::parse("TRUE"), Ok(Literal::Bool(true)));
        assert_eq!(Literal::parse("T#1m30s"), Ok(Literal::Time(90_000)));
        assert_eq!(Literal::parse("time#250ms"), Ok(Literal::Time(250)));
        assert_eq!(Literal::parse("t#1h_2s"), Ok(Literal::Time(3_602_000)));
    }

    #[test]
    fn malformed_literals_say_what_is_wrong() {
        for bad in [
            "",
            "-",
            "1.",
            "1.e5",
            "abc",
            "16#G",
            "3#1",
            "T#",
            "T#5x",
            "1..2",
            "99999999999999999999",
            "1e999",
        ] {
            assert!(Literal::parse(bad).is_err(), "{bad:?} should fail");
        }
    }

    #[test]
    fn values_check_their_range() {
        assert_eq!(Value::parse("32767", DataType::Int), Ok(Value::Int(32767)));
        assert!(
            Value::parse("32768", DataType::Int)
                .unwrap_err()
                .to_string()
                .contains("out of range")
        );
        assert!(Value::parse("2", DataType::Bool).is_err());
        assert_eq!(Value::parse("1", DataType::Bool), Ok(Value::Bool(true)));
        assert!(Value::parse("1.5", DataType::Dint).is_err());
        assert_eq!(Value::parse("7", DataType::Real), Ok(Value::Real(7.0)));
        assert_eq!(Value::parse("T#2s", DataType::Time), Ok(Value::Time(2000)));
        assert!(Value::parse("0", DataType::Timer).is_err());
    }

    #[test]
    fn reals_print_in_shortest_exact_form() {
        let v = Value::Real(0.843_108_5);
        assert_eq!(v.to_string(), "0.8431085");
        let back: f32 = v.to_string().parse().unwrap();
        assert_eq!(Value::Real(back), v);
        assert_eq!(Value::Real(1.0).to_string(), "1");
        assert_eq!(Value::Bool(true).to_string(), "1");
        // The exponent form where it is shorter, never losing a bit.
        for (v, text) in [
            (f32::MAX, "3.4028235e38"),
            (1e-7, "1e-7"),
            (100000.0, "100000"),
            (-0.5, "-0.5"),
            (2e16, "2e16"),
        ] {
            assert_eq!(Value::Real(v).to_string(), text);
            assert_eq!(text.parse::<f32>(), Ok(v));
        }
        assert_eq!(Value::Lreal(1e300).to_string(), "1e300");
    }
}
