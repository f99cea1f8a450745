//! `GET /api/instructions`: the ladder palette.

use crate::reply::Instruction;
use alba_compiler::ladder::{Arg, Mnemonic, ast::Group};
use axum::Json;

fn arg_name(a: Arg) -> &'static str {
    match a {
        Arg::BitIn => "bit_in",
        Arg::BitOut => "bit_out",
        Arg::Timer => "timer",
        Arg::Counter => "counter",
        Arg::TimerOrCounter => "timer_or_counter",
        Arg::Preset => "preset",
        Arg::Accum => "accum",
        Arg::NumIn => "num_in",
        Arg::NumOut => "num_out",
        Arg::Label => "label",
        Arg::Expr => "expr",
        Arg::Pid => "pid",
    }
}

fn group_name(g: Group) -> &'static str {
    match g {
        Group::Bit => "bit",
        Group::Timer => "timer",
        Group::Counter => "counter",
        Group::Compare => "compare",
        Group::Math => "math",
        Group::MoveLogic => "move",
        Group::Trig => "trig",
        Group::Flow => "flow",
        Group::Special => "special",
    }
}

pub async fn list() -> Json<Vec<Instruction>> {
    Json(
        Mnemonic::ALL
            .iter()
            .filter(|m| m.group() != Group::Special)
            .map(|m| Instruction {
                mnemonic: m.name().to_string(),
                group: group_name(m.group()).to_string(),
                output: m.is_output(),
                args: m.args().iter().map(|a| arg_name(*a).to_string()).collect(),
                doc: m.doc().to_string(),
            })
            .collect(),
    )
}
