//! Tag values as JSON (docs/api.md "Values"): what the API sends and
//! accepts, and what the retain file stores.

use alba_model::{DataType, Value};
use serde_json::Value as Json;

/// A value as JSON: booleans, integers, and numbers for reals (`null` for a
/// non-finite real, which JSON cannot hold).
pub fn to_json(v: Value) -> Json {
    match v {
        Value::Bool(b) => Json::Bool(b),
        Value::Sint(x) => x.into(),
        Value::Int(x) => x.into(),
        Value::Dint(x) | Value::Time(x) => x.into(),
        Value::Lint(x) => x.into(),
        // The shortest decimal that reads back as the same f32 (0.1, not 0.10000000149011612).
        Value::Real(x) => x
            .to_string()
            .parse::<f64>()
            .ok()
            .and_then(serde_json::Number::from_f64)
            .map_or(Json::Null, Json::Number),
        Value::Lreal(x) => serde_json::Number::from_f64(x).map_or(Json::Null, Json::Number),
    }
}

/// Why a JSON value does not fit a place's type ([`from_json`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ValueError {
    #[error("expected an integer for a {ty}, got {got}")]
    NotAnInteger { ty: DataType, got: &'static str },
    #[error("{value} is out of range for {ty} ({lo} to {hi})")]
    IntOutOfRange { value: i64, ty: DataType, lo: i64, hi: i64 },
    #[error("expected true, false, 0 or 1 for a BOOL, got {got}")]
    NotABool { got: &'static str },
    #[error("expected a number for a {ty}, got {got}")]
    NotANumber { ty: DataType, got: &'static str },
    #[error("{value:e} is out of range for REAL")]
    RealOutOfRange { value: f64 },
    #[error("a {ty} is a structure: write one of its members")]
    Structure { ty: DataType },
}

impl ValueError {
    /// A number of the right kind that the type cannot hold (else the
    /// value is of the wrong kind).
    pub fn is_out_of_range(&self) -> bool {
        matches!(
            self,
            ValueError::IntOutOfRange { .. } | ValueError::RealOutOfRange { .. }
        )
    }
}

/// A JSON value for a place of type `ty`, or why it does not fit.
pub fn from_json(j: &Json, ty: DataType) -> Result<Value, ValueError> {
    let int_range = |lo: i64, hi: i64| -> Result<i64, ValueError> {
        let v = match j {
            Json::Number(n) => n.as_i64().or_else(|| {
                n.as_f64()
                    .filter(|f| f.fract() == 0.0 && f.abs() < 9.2e18)
                    .map(|f| f as i64)
            }),
            Json::Bool(b) if ty == DataType::Bool => Some(i64::from(*b)),
            _ => None,
        }
        .ok_or_else(|| ValueError::NotAnInteger { ty, got: kind(j) })?;
        if (lo..=hi).contains(&v) {
            Ok(v)
        } else {
            Err(ValueError::IntOutOfRange { value: v, ty, lo, hi })
        }
    };
    Ok(match ty {
        DataType::Bool => match j {
            Json::Bool(b) => Value::Bool(*b),
            Json::Number(_) => Value::Bool(int_range(0, 1)? == 1),
            _ => return Err(ValueError::NotABool { got: kind(j) }),
        },
        DataType::Sint => Value::Sint(int_range(i8::MIN.into(), i8::MAX.into())? as i8),
        DataType::Int => Value::Int(int_range(i16::MIN.into(), i16::MAX.into())? as i16),
        DataType::Dint => Value::Dint(int_range(i32::MIN.into(), i32::MAX.into())? as i32),
        DataType::Time => Value::Time(int_range(i32::MIN.into(), i32::MAX.into())? as i32),
        DataType::Lint => Value::Lint(int_range(i64::MIN, i64::MAX)?),
        DataType::Real | DataType::Lreal => {
            let f = j.as_f64().ok_or_else(|| ValueError::NotANumber { ty, got: kind(j) })?;
            if ty == DataType::Real {
                if f.is_finite() && f.abs() > f64::from(f32::MAX) {
                    return Err(ValueError::RealOutOfRange { value: f });
                }
                Value::Real(f as f32)
            } else {
                Value::Lreal(f)
            }
        }
        other => return Err(ValueError::Structure { ty: other }),
    })
}

fn kind(j: &Json) -> &'static str {
    match j {
        Json::Null => "null",
        Json::Bool(_) => "a boolean",
        Json::Number(_) => "a number",
        Json::String(_) => "a string",
        Json::Array(_) => "an array",
        Json::Object(_) => "an object",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn values_round_trip_and_bad_ones_are_refused_with_reasons() {
        for (j, ty, v) in [
            (json!(true), DataType::Bool, Value::Bool(true)),
            (json!(0), DataType::Bool, Value::Bool(false)),
            (json!(-7), DataType::Int, Value::Int(-7)),
            (json!(5.0), DataType::Dint, Value::Dint(5)),
            (json!(1.5), DataType::Real, Value::Real(1.5)),
            (json!(3), DataType::Lreal, Value::Lreal(3.0)),
        ] {
            assert_eq!(from_json(&j, ty), Ok(v), "{j}");
        }
        assert_eq!(to_json(Value::Real(1.5)), json!(1.5));
        assert_eq!(to_json(Value::Real(0.1)), json!(0.1));
        assert_eq!(to_json(Value::Real(37.503746)), json!(37.503746));
        assert_eq!(to_json(Value::Real(f32::NAN)), Json::Null);
        let err = |j: Json, ty| from_json(&j, ty).unwrap_err().to_string();
        assert_eq!(
            err(json!(40000), DataType::Int),
            "40000 is out of range for INT (-32768 to 32767)"
        );
        assert_eq!(
            err(json!("5"), DataType::Dint),
            "expected an integer for a DINT, got a string"
        );
        assert_eq!(
            err(json!(1.5), DataType::Dint),
            "expected an integer for a DINT, got a number"
        );
        assert_eq!(err(json!(2), DataType::Bool), "2 is out of range for BOOL (0 to 1)");
        assert_eq!(err(json!(1e39), DataType::Real), "1e39 is out of range for REAL");
        assert_eq!(
            err(json!(1), DataType::Timer),
            "a TIMER is a structure: write one of its members"
        );
    }
}
