//! LTIME, DATE, TIME_OF_DAY and DATE_AND_TIME on LINT slots (ADR 0017):
//! LTIME in nanoseconds; DATE, TOD and DT in milliseconds (a DATE and a DT
//! since 1970-01-01 00:00, a TOD since midnight). Their arithmetic and
//! conversions are existing LINT operations; nothing was added to the IR.

use super::*;

const DAY_MS: i64 = 86_400_000;
const NS_PER_MS: i64 = 1_000_000;

/// Days from 1970-01-01 to the civil date `y-m-d` (proleptic Gregorian).
fn days_from_civil(y: i64, m: i64, d: i64) -> i64 {
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let mp = (m + 9) % 12;
    let doy = (153 * mp + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

/// `2024-01-31` in milliseconds since 1970-01-01.
fn date_ms(v: &str) -> Option<i64> {
    let mut it = v.split('-');
    let y: i64 = it.next()?.parse().ok()?;
    let m: i64 = it.next()?.parse().ok()?;
    let d: i64 = it.next()?.parse().ok()?;
    let leap = (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
    let days_in = [31, if leap { 29 } else { 28 }, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31];
    if it.next().is_some() || !(1..=12).contains(&m) || d < 1 || d > days_in[(m - 1) as usize] {
        return None;
    }
    Some(days_from_civil(y, m, d) * DAY_MS)
}

/// `12:30:15.250` (seconds optional) in milliseconds since midnight.
fn tod_ms(v: &str) -> Option<i64> {
    let mut it = v.split(':');
    let h: i64 = it.next()?.parse().ok()?;
    let m: i64 = it.next()?.parse().ok()?;
    let s: f64 = match it.next() {
        Some(s) => s.parse().ok()?,
        None => 0.0,
    };
    if it.next().is_some() || !(0..24).contains(&h) || !(0..60).contains(&m) || !(0.0..60.0).contains(&s) {
        return None;
    }
    Some(h * 3_600_000 + m * 60_000 + (s * 1000.0).round() as i64)
}

/// The type and the value of a date or time literal (`D#…`, `TOD#…`,
/// `DT#…`, `LTIME#…`); `None` for another kind of literal.
pub(super) fn date_literal(t: &str, v: &str) -> Option<Result<(Ty, i64), String>> {
    let v = v.replace('_', "");
    let (ty, parsed) = match t.to_ascii_uppercase().as_str() {
        "D" | "DATE" => (Ty::Date, date_ms(&v)),
        "TOD" | "TIME_OF_DAY" => (Ty::Tod, tod_ms(&v)),
        "DT" | "DATE_AND_TIME" => {
            // `2024-01-31-12:30:00`: the date is the first three fields.
            let at = v.match_indices('-').nth(2).map(|(i, _)| i);
            let parsed = at.and_then(|i| Some(date_ms(&v[..i])? + tod_ms(&v[i + 1..])?));
            (Ty::Dt, parsed)
        }
        "LT" | "LTIME" => {
            let ns = crate::parse::duration_ns(v.trim_start_matches('-'));
            (Ty::Ltime, ns.map(|n| if v.starts_with('-') { -n } else { n }))
        }
        _ => return None,
    };
    Some(parsed.map(|x| (ty.clone(), x)).ok_or_else(|| {
        let example = match ty {
            Ty::Date => "D#2024-01-31",
            Ty::Tod => "TOD#12:30:15.5",
            Ty::Dt => "DT#2024-01-31-12:30:00",
            _ => "LTIME#1s250ms10us",
        };
        format!("`{t}#{v}` is not a valid {ty} literal; write it like {example}")
    }))
}

pub(super) fn is_date(t: &Ty) -> bool {
    matches!(t, Ty::Ltime | Ty::Date | Ty::Tod | Ty::Dt)
}

impl Lower<'_> {
    /// `v` (a value of `ty`) in a LINT slot.
    fn as_l(&mut self, v: V) -> alba_ir::op::L {
        match self.b.convert(v, Class::L, self.elem) {
            V::L(l) => l,
            _ => self.b.const_l(0),
        }
    }

    /// A binary operator with a date or time operand (the 3rd edition's
    /// ADD/SUB_DT_TIME, SUB_DATE_DATE, … and comparisons of one type).
    pub(super) fn date_binary(&mut self, op: BinOp, a: (V, &Ty), b: (V, &Ty), span: Span) -> R<(Val, Ty)> {
        let (ta, tb) = (a.1.clone(), b.1.clone());
        let (x, y) = (self.as_l(a.0), self.as_l(b.0));
        let cmp = match op {
            BinOp::Eq => Some(Cmp::Eq),
            BinOp::Ne => Some(Cmp::Ne),
            BinOp::Lt => Some(Cmp::Lt),
            BinOp::Gt => Some(Cmp::Gt),
            BinOp::Le => Some(Cmp::Le),
            BinOp::Ge => Some(Cmp::Ge),
            _ => None,
        };
        if let Some(c) = cmp {
            if ta != tb {
                return Err(type_error(
                    span,
                    format!("`{}` of {ta} and {tb}: the types differ", op.text()),
                ));
            }
            let r = self.b.temp_b();
            self.emit(Op::CmpL(c, x, y));
            self.emit(Op::Ote(r));
            self.emit(Op::True);
            return Ok((Val::B(r), Ty::Bool));
        }
        let t = self.b.temp_l();
        let result = match (op, &ta, &tb) {
            // DT/TOD ± TIME: milliseconds on both sides.
            (BinOp::Add | BinOp::Sub, Ty::Dt | Ty::Tod, Ty::Time) => {
                let o = if op == BinOp::Add { IBin::Add } else { IBin::Sub };
                self.emit(Op::BinL(o, x, y, t));
                ta.clone()
            }
            (BinOp::Add | BinOp::Sub, Ty::Ltime, Ty::Ltime) => {
                let o = if op == BinOp::Add { IBin::Add } else { IBin::Sub };
                self.emit(Op::BinL(o, x, y, t));
                Ty::Ltime
            }
            (BinOp::Mul | BinOp::Div, Ty::Ltime, i) if i.is_int() => {
                let o = if op == BinOp::Mul { IBin::Mul } else { IBin::Div };
                self.emit(Op::BinL(o, x, y, t));
                Ty::Ltime
            }
            // DATE - DATE, TOD - TOD, DT - DT: a TIME (32-bit milliseconds:
            // more than 24 days is the engine's overflow fault).
            (BinOp::Sub, Ty::Date | Ty::Tod | Ty::Dt, _) if ta == tb => {
                self.emit(Op::BinL(IBin::Sub, x, y, t));
                let i = self.b.temp_i();
                self.emit(Op::Cvt(alba_ir::op::Cvt::LI(t, i)));
                return Ok((Val::N(V::I(i)), Ty::Time));
            }
            _ => {
                return Err(type_error(
                    span,
                    format!(
                        "`{}` of {ta} and {tb} is not defined (DT/TOD ± TIME, DATE/TOD/DT − the same, LTIME ± LTIME, LTIME * / an integer)",
                        op.text()
                    ),
                ));
            }
        };
        Ok((Val::N(V::L(t)), result))
    }

    /// A conversion from or to a date or time type (`TIME_TO_LTIME`,
    /// `DT_TO_DATE`, `DT_TO_TOD`, `LTIME_TO_LINT`, …); `None` when neither
    /// type is one.
    pub(super) fn date_conversion(&mut self, from: &Ty, to: &Ty, arg: &Expr, f: &str) -> Option<R<(Val, Ty)>> {
        if !is_date(from) && !is_date(to) {
            return None;
        }
        Some(self.date_convert(from, to, arg, f))
    }

    fn date_convert(&mut self, from: &Ty, to: &Ty, arg: &Expr, f: &str) -> R<(Val, Ty)> {
        let (v, ty) = self.eval(arg, Some(from))?;
        let Val::N(v) = v else {
            return Err(type_error(arg.span, format!("{f} takes {}, not BOOL", an(from))));
        };
        if ty != *from && !(from.is_int() && widens(&ty, from)) {
            return Err(type_error(arg.span, format!("{f} takes {}, not {}", an(from), an(&ty))));
        }
        let x = self.as_l(v);
        let t = self.b.temp_l();
        let day = self.b.const_l(DAY_MS);
        let ns = self.b.const_l(NS_PER_MS);
        let _ = match (from, to) {
            (a, b) if a == b => self.emit(Op::UnL(IUn::Mov, x, t)),
            (Ty::Time, Ty::Ltime) => self.emit(Op::BinL(IBin::Mul, x, ns, t)),
            (Ty::Ltime, Ty::Time) => {
                self.emit(Op::BinL(IBin::Div, x, ns, t));
                let i = self.b.temp_i();
                self.emit(Op::Cvt(alba_ir::op::Cvt::LI(t, i)));
                return Ok((Val::N(V::I(i)), Ty::Time));
            }
            (Ty::Dt, Ty::Date) => {
                let m = self.b.temp_l();
                self.emit(Op::BinL(IBin::Mod, x, day, m));
                self.emit(Op::BinL(IBin::Sub, x, m, t))
            }
            (Ty::Dt, Ty::Tod) => self.emit(Op::BinL(IBin::Mod, x, day, t)),
            (Ty::Date, Ty::Dt) => self.emit(Op::UnL(IUn::Mov, x, t)),
            // The count itself: nanoseconds of an LTIME, milliseconds of the others.
            (d, Ty::Lint) if is_date(d) => self.emit(Op::UnL(IUn::Mov, x, t)),
            (Ty::Lint | Ty::Dint | Ty::Int | Ty::Sint, d) if is_date(d) => self.emit(Op::UnL(IUn::Mov, x, t)),
            _ => {
                return Err(not_supported(
                    arg.span,
                    format!("{f}: the conversion from {from} to {to} is not supported"),
                ));
            }
        };
        Ok((Val::N(V::L(t)), to.clone()))
    }

    /// CONCAT_DATE_TOD(d, tod): the DATE_AND_TIME of both.
    pub(super) fn concat_date_tod(&mut self, args: &[&Expr], span: Span) -> R<(Val, Ty)> {
        if args.len() != 2 {
            return Err(type_error(
                span,
                format!("CONCAT_DATE_TOD takes 2 argument(s), not {}", args.len()),
            ));
        }
        let mut parts = Vec::new();
        for (e, want) in args.iter().zip([Ty::Date, Ty::Tod]) {
            let (v, ty) = self.eval(e, Some(&want))?;
            match v {
                Val::N(x) if ty == want => parts.push(self.as_l(x)),
                _ => {
                    return Err(type_error(
                        e.span,
                        format!("CONCAT_DATE_TOD takes {}, not {}", an(&want), an(&ty)),
                    ));
                }
            }
        }
        let t = self.b.temp_l();
        self.emit(Op::BinL(IBin::Add, parts[0], parts[1], t));
        Ok((Val::N(V::L(t)), Ty::Dt))
    }
}
