//! Byte code (issue 19): every example and 1 000 random programs survive
//! encode → decode unchanged and run the same on the engine as the program
//! they came from (every slot of every area after every scan, under random
//! inputs); malformed byte code — truncated, a flipped bit, a wrong CRC, a
//! mutated body re-signed — is refused with a reason and never panics.

mod common;

use alba_arduino::bytecode::{self, DecodeError, HEADER_LEN};
use alba_arduino::sketch::{Target, control_program};
use alba_engine::Engine;
use alba_ir::{B, I, Place, Program};
use alba_model::board::{Model, PinMap};
use alba_model::{DataType, Value};
use std::path::Path;
use std::sync::Arc;

fn root() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

fn compile(dir: &Path) -> Program {
    let c = alba_load::compile_dir(dir);
    c.program
        .unwrap_or_else(|| panic!("{} does not compile: {:?}", dir.display(), c.diagnostics))
}

fn host(p: &Program) -> bytecode::Bytecode {
    bytecode::encode_program(&control_program(p), 10, 0, 0xA1BA, &[]).expect("encodes")
}

/// Runs both programs `scans` scans of 10 ms with the same random inputs and
/// compares their whole memory after every scan.
fn same_runs(a: &Program, b: &Program, scans: u64, seed: u64, what: &str) {
    let (mut x, mut y) = (
        Engine::new(Arc::new(a.clone())).expect("verifies"),
        Engine::new(Arc::new(b.clone())).expect("decoded program verifies"),
    );
    let mut r = common::Rng(seed | 1);
    let lay = &a.layout;
    for k in 0..scans {
        if lay.di.len > 0 && r.below(3) == 0 {
            let slot = lay.di.base + r.below(u64::from(lay.di.len)) as u32;
            let v = Value::Bool(r.below(2) == 1);
            x.write(Place::Bool(B(slot)), v);
            y.write(Place::Bool(B(slot)), v);
        }
        if lay.ai.len > 0 && r.below(5) == 0 {
            let slot = lay.ai.base + r.below(u64::from(lay.ai.len)) as u32;
            let v = Value::Int(r.below(1024) as i16);
            x.write(Place::Int(I(slot), DataType::Int), v);
            y.write(Place::Int(I(slot), DataType::Int), v);
        }
        let (ra, rb) = (x.scan(k * 10), y.scan(k * 10));
        assert_eq!(ra.is_ok(), rb.is_ok(), "{what}: scan {k}");
        assert_eq!(x.memory(), y.memory(), "{what}: memory after scan {k}");
    }
}

fn round_trip(p: &Program, what: &str) -> Program {
    let bc = host(p);
    let d = bytecode::decode(&bc.bytes).unwrap_or_else(|e| panic!("{what}: {e}"));
    let c = control_program(p);
    assert_eq!(d.program.ops, c.ops, "{what}: ops");
    assert_eq!(d.program.init, c.init, "{what}: initial memory");
    assert_eq!(d.program.layout.system, c.layout.system, "{what}: system slots");
    assert_eq!(d.program_id, 0xA1BA);
    d.program
}

#[test]
fn every_example_round_trips_and_runs_the_same() {
    let mut names: Vec<_> = std::fs::read_dir(root().join("examples"))
        .expect("examples")
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert!(names.len() >= 10);
    for name in names {
        let p = compile(&root().join("examples").join(&name));
        let decoded = round_trip(&p, &name);
        same_runs(&control_program(&p), &decoded, 500, 7, &name);
    }
}

#[test]
fn a_thousand_random_programs_round_trip_and_run_the_same() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("bytecode-random");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("dir");
    std::fs::write(
        dir.join("alba.toml"),
        "name = \"random\"\nscan_ms = 10\nprograms = [\"main.lad\"]\n",
    )
    .expect("write");
    // (the generator sometimes gives one counter two presets, which the compiler refuses: skipped)
    let mut ran = 0;
    for seed in 1..=3000u64 {
        let (tags, lad) = common::random_ladder(seed);
        std::fs::write(dir.join("tags.csv"), tags).expect("write");
        std::fs::write(dir.join("main.lad"), &lad).expect("write");
        let Some(p) = alba_load::compile_dir(&dir).program else {
            continue;
        };
        let what = format!("random program {seed}:\n{lad}");
        let decoded = round_trip(&p, &what);
        same_runs(&p, &decoded, 60, seed, &what);
        ran += 1;
        if ran == 1000 {
            return;
        }
    }
    panic!("only {ran} random programs compiled");
}

#[test]
fn a_board_program_carries_its_wiring_and_the_sketchs_program_id() {
    let p = compile(&root().join("examples/tank"));
    let t = Target {
        model: Model::Uno,
        map: PinMap::preset("aurora").expect("aurora"),
        active_low: false,
        scan_ms: 10,
        monitor: true,
        power_up_on: vec![],
    };
    let sketch = alba_arduino::sketch::generate(&p, "tank", &t).expect("the tank fits the Uno");
    let bc = bytecode::encode(&p, "tank", &t).expect("encodes");
    assert_eq!(bc.program_id, sketch.program_id);
    let d = bytecode::decode(&bc.bytes).expect("decodes");
    assert_eq!(d.scan_ms, 10);
    assert_eq!(d.wiring.len(), sketch.wiring.len());
    for (w, (address, _, slot)) in sketch.wiring.iter().zip(&d.wiring) {
        assert_eq!((w.address, w.slot), (*address, *slot));
    }
    // Small enough for the Uno's 1 KB of EEPROM, with room to spare.
    assert!(bc.bytes.len() < 1024, "{} bytes", bc.bytes.len());
    // What the sketch refuses, byte code refuses the same way (LREAL on an AVR).
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("bytecode-lreal");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("dir");
    std::fs::write(
        dir.join("alba.toml"),
        "name = \"x\"\nscan_ms = 10\nprograms = [\"main.lad\"]\n",
    )
    .expect("write");
    std::fs::write(
        dir.join("tags.csv"),
        "name,type,address,initial,retain,description\nX,LREAL,,,,\nQ,BOOL,DO:2/0,,,\n",
    )
    .expect("write");
    std::fs::write(dir.join("main.lad"), "GRT(X,1.0)OTE(Q);\n").expect("write");
    let refused = bytecode::encode(&compile(&dir), "x", &t).expect_err("refused");
    assert!(refused[0].message.contains("LREAL"), "{:?}", refused);
}

fn aurora(model: Model) -> Target {
    Target {
        model,
        map: PinMap::preset("aurora").expect("aurora"),
        active_low: false,
        scan_ms: 10,
        monitor: true,
        power_up_on: vec![],
    }
}

/// `bytes` with its body's CRC made good again.
fn resign(mut bytes: Vec<u8>) -> Vec<u8> {
    let crc = crc32fast_hash(&bytes[HEADER_LEN..]);
    bytes[20..24].copy_from_slice(&crc.to_le_bytes());
    bytes
}

#[test]
fn a_board_refuses_byte_code_for_another_board_or_beyond_its_interpreter() {
    let p = compile(&root().join("examples/start-stop"));
    let (uno, mega) = (aurora(Model::Uno), aurora(Model::Mega));
    let bc = bytecode::encode(&p, "start-stop", &uno).expect("encodes");
    let d = bytecode::decode_for(&bc.bytes, &uno).expect("the Uno runs it");
    assert_eq!(d.board_id, bytecode::board_id(&uno));
    let board_err = |bytes: &[u8], t: &Target| match bytecode::decode_for(bytes, t) {
        Err(DecodeError::Board(m)) => m,
        other => panic!("{other:?}"),
    };
    // Another board, another pin map, another output polarity: another board id.
    let mut s7 = uno.clone();
    s7.map = PinMap::preset("s7").expect("s7");
    let mut low = uno.clone();
    low.active_low = true;
    let ids = [&uno, &mega, &s7, &low].map(bytecode::board_id);
    for (k, id) in ids.iter().enumerate() {
        assert!(!ids[..k].contains(id), "{ids:?}");
    }
    for t in [&mega, &s7, &low] {
        assert!(board_err(&bc.bytes, t).contains("another board or pin map"), "{t:?}");
    }
    // The header's board id is outside the CRC: changed, it is still refused.
    let mut other = bc.bytes.clone();
    other[6..8].copy_from_slice(&bytecode::board_id(&mega).to_le_bytes());
    assert!(bytecode::decode(&other).is_ok(), "well formed");
    assert!(board_err(&other, &uno).contains("another board"));
    // Start wired to D11, which is not DI:1/0's pin (D2) on the aurora map.
    let at = (0..bc.bytes.len())
        .find(|k| bc.bytes[*k..].starts_with(&[0, 0, 0, 2, 6, 0]))
        .expect("Start's wire");
    let mut v = bc.bytes.clone();
    v[at + 3] = 11;
    let v = resign(v);
    assert!(bytecode::decode(&v).is_ok(), "well formed");
    assert!(
        board_err(&v, &uno).contains("DI:1/0 is wired to pin byte 0x0b"),
        "{}",
        board_err(&v, &uno)
    );
    // PID: well formed, engine-defined, not on the board (the export refuses it).
    let pid = compile(&root().join("examples/pid-level"));
    let host =
        bytecode::encode_program(&control_program(&pid), 10, bytecode::board_id(&uno), 0, &[]).expect("host form");
    assert!(bytecode::decode(&host.bytes).is_ok());
    assert!(
        board_err(&host.bytes, &uno).contains("(Pid("),
        "{}",
        board_err(&host.bytes, &uno)
    );
    // What the Uno's interpreter cannot hold, encode refuses with the reason.
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("bytecode-big");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("dir");
    std::fs::write(
        dir.join("alba.toml"),
        "name = \"big\"\nscan_ms = 10\nprograms = [\"main.lad\"]\n",
    )
    .expect("write");
    let mut tags = String::from("name,type,address,initial,retain,description\nQ,BOOL,DO:2/0,,,\n");
    for k in 0..60 {
        tags += &format!("R{k},REAL,,,,\n");
    }
    std::fs::write(dir.join("tags.csv"), tags).expect("write");
    std::fs::write(dir.join("main.lad"), "GRT(R0,R59)OTE(Q);\n").expect("write");
    let e = bytecode::encode(&compile(&dir), "big", &uno).expect_err("60 REALs on the Uno");
    assert!(
        e[0].message
            .contains("60 REAL slots; the Arduino Uno's interpreter holds 48"),
        "{:?}",
        e[0].message
    );
    assert!(
        bytecode::encode(&compile(&dir), "big", &mega).is_ok(),
        "the Mega holds them"
    );
}

#[test]
fn malformed_byte_code_is_refused_with_a_reason_and_never_panics() {
    let p = compile(&root().join("examples/tank-plant"));
    let good = host(&p).bytes;
    // Every truncation.
    for n in 0..good.len() {
        assert!(bytecode::decode(&good[..n]).is_err(), "{n} bytes accepted");
    }
    let mut bad = good.clone();
    bad[0] = b'X';
    assert!(matches!(bytecode::decode(&bad), Err(DecodeError::Magic(_))));
    let mut bad = good.clone();
    bad[4] = 9;
    assert_eq!(
        bytecode::decode(&bad).unwrap_err().to_string(),
        "byte code format 9; this version reads 3"
    );
    // A flipped bit anywhere in the body: the CRC says so.
    for k in (HEADER_LEN..good.len()).step_by(7) {
        let mut bad = good.clone();
        bad[k] ^= 0x10;
        assert!(
            matches!(bytecode::decode(&bad), Err(DecodeError::Crc { .. })),
            "byte {k}"
        );
    }
    // Mutated bodies re-signed with a good CRC: decoded or refused, never a panic, and
    // whatever decodes passes the program checks the engine relies on and runs.
    let mut r = common::Rng(42);
    let mut refused = 0;
    for _ in 0..20_000 {
        let mut bad = good.clone();
        for _ in 0..1 + r.below(4) {
            let k = HEADER_LEN + r.below((good.len() - HEADER_LEN) as u64) as usize;
            bad[k] = r.next() as u8;
        }
        let crc = crc32fast_hash(&bad[HEADER_LEN..]);
        bad[20..24].copy_from_slice(&crc.to_le_bytes());
        match bytecode::decode(&bad) {
            Ok(d) => {
                // It verified: the engine runs it without a panic (faults are fine).
                let mut e = Engine::new(Arc::new(d.program)).expect("a verified program runs");
                for k in 0..3 {
                    let _ = e.scan(k * 10);
                }
            }
            Err(e) => {
                refused += 1;
                assert!(!e.to_string().is_empty());
            }
        }
    }
    assert!(refused > 1000, "only {refused} of 20 000 mutations refused");
}

/// CRC-32 (IEEE), bit by bit: the format's checksum, computed independently.
fn crc32fast_hash(b: &[u8]) -> u32 {
    let mut c = !0u32;
    for &x in b {
        c ^= u32::from(x);
        for _ in 0..8 {
            c = if c & 1 != 0 { (c >> 1) ^ 0xEDB8_8320 } else { c >> 1 };
        }
    }
    !c
}

#[test]
fn timers_keep_their_time_base_and_an_undefined_base_is_refused() {
    // The engine's golden of the seconds base: TON, TOF, RTO in s.
    let p = compile(&root().join("crates/engine/tests/golden/timer-base-s"));
    let back = round_trip(&p, "timer-base-s");
    let bases: Vec<alba_ir::TimeBase> = back
        .ops
        .iter()
        .filter_map(|op| match op {
            alba_ir::Op::Ton(_, b) | alba_ir::Op::Tof(_, b) | alba_ir::Op::Rto(_, b) => Some(*b),
            _ => None,
        })
        .collect();
    assert_eq!(bases, [alba_ir::TimeBase::S; 3]);
    // The RTO (opcode 0x12) with base code 3 (s): code 9 is no base.
    let good = host(&p).bytes;
    let refused = (HEADER_LEN..good.len() - 1)
        .filter(|&k| good[k] == 0x12 && good[k + 1] == 3)
        .filter(|&k| {
            let mut bad = good.clone();
            bad[k + 1] = 9;
            bytecode::decode(&resign(bad)).is_err_and(|e| e.to_string().contains("time base 9 is not defined"))
        })
        .count();
    assert_eq!(refused, 1, "the RTO's base byte");
}
