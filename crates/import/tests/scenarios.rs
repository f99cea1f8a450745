//! Imported programs run in Alba's simulator: the L5X conveyor and the
//! AuroraLD plant against the same logic written natively in Alba (random
//! inputs, outputs compared by address on every scan), and the PLCopen
//! constructs against the IEC behaviour they must keep.

use alba_import::Options;
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

/// Runs `alba sim` on a project: the trace rows as (time, column → value).
fn sim(dir: &Path, stimulus: &str, cols: &[&str], until: u64, every: u64) -> Vec<(u64, HashMap<String, String>)> {
    let c = alba_load::compile_dir(dir);
    let mut msg = String::new();
    for d in &c.diagnostics {
        msg.push_str(&d.short(c.files()));
    }
    let scan_ms = c.project.config.as_ref().map(|c| u64::from(c.scan_ms)).expect("config");
    let prog = c
        .program
        .unwrap_or_else(|| panic!("{} does not compile: {msg}", dir.display()));
    let mut files = alba_diag::Files::new();
    let fid = files.add("stimulus.csv", stimulus.to_string());
    let stim = alba_engine::sim::Stimulus::parse(stimulus, fid, &prog.layout)
        .unwrap_or_else(|d| panic!("stimulus: {}", d.iter().map(|d| d.short(&files)).collect::<String>()));
    let columns = alba_engine::sim::columns(&cols.join(","), &prog.layout).expect("columns");
    let mut engine = alba_engine::Engine::new(Arc::new(prog)).expect("engine");
    let mut out = Vec::new();
    let opt = alba_engine::sim::SimOptions {
        scan_ms,
        until_ms: until,
        every_ms: every,
    };
    alba_engine::sim::run(&mut engine, &stim, &columns, opt, &mut out).expect("sim");
    let text = String::from_utf8(out).expect("utf8");
    let mut lines = text.lines();
    let head: Vec<String> = lines.next().unwrap_or("").split(',').map(str::to_string).collect();
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            let t = f[0].parse().unwrap_or(0);
            let m = head
                .iter()
                .skip(1)
                .zip(f.iter().skip(1))
                .map(|(h, v)| (h.clone(), (*v).to_string()))
                .collect();
            (t, m)
        })
        .collect()
}

fn import(fixture: &str) -> tempfile::TempDir {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(fixture);
    let tmp = tempfile::tempdir().expect("tmp");
    alba_import::import(&path, &tmp.path().join("p"), &Options::default()).expect("import");
    tmp
}

#[test]
fn l5x_conveyor_equals_the_native_program() {
    let tmp = import("l5x/conveyor.L5X");
    let imported = tmp.path().join("p");
    let native = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/native/conveyor");
    // Random inputs on the four digital inputs, every 20 ms scan for 60 s.
    let mut x: u64 = 0x2545_F491_4F6C_DD1D;
    let mut stim = String::from("time_ms,tag,value\n");
    let mut last = [2u64; 4];
    for k in 0..3000u64 {
        for (i, v) in last.iter_mut().enumerate() {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            // Stop (NC) is mostly closed; the others change now and then.
            let new = if i == 1 {
                u64::from(!x.is_multiple_of(50))
            } else if x.is_multiple_of(9) {
                1 - (*v % 2)
            } else {
                *v % 2
            };
            if new != *v {
                *v = new;
                stim.push_str(&format!("{},DI:1/{i},{new}\n", k * 20));
            }
        }
    }
    let cols = ["DO:2/0", "DO:2/1", "DO:2/2", "DI:1/0", "DI:1/2", "Batches"];
    let a = sim(&imported, &stim, &cols, 60_000, 20);
    let b = sim(&native, &stim, &cols, 60_000, 20);
    assert_eq!(a.len(), b.len());
    let mut changes = 0;
    for ((t, ra), (_, rb)) in a.iter().zip(&b) {
        for c in cols {
            assert_eq!(ra.get(c), rb.get(c), "{c} at t = {t} ms");
        }
        if ra.get("DO:2/0").map(String::as_str) == Some("1") {
            changes += 1;
        }
    }
    assert!(changes > 10, "the belt never ran");
    // Speed is program-scoped in MainProgram and Alarms: compare both.
    let a = sim(&imported, &stim, &["Speed", "Alarms_Speed", "Parts.ACC"], 60_000, 20);
    let b = sim(&native, &stim, &["Speed", "Speed2", "Parts.ACC"], 60_000, 20);
    for ((t, ra), (_, rb)) in a.iter().zip(&b) {
        assert_eq!(ra.get("Speed"), rb.get("Speed"), "Speed at {t}");
        assert_eq!(ra.get("Alarms_Speed"), rb.get("Speed2"), "Alarms.Speed at {t}");
        assert_eq!(ra.get("Parts.ACC"), rb.get("Parts.ACC"), "Parts.ACC at {t}");
    }
}

/// The value of `col` at time `t` (the row of the scan at t).
fn at<'a>(rows: &'a [(u64, HashMap<String, String>)], t: u64, col: &str) -> &'a str {
    rows.iter()
        .find(|(rt, _)| *rt == t)
        .and_then(|(_, m)| m.get(col))
        .map(String::as_str)
        .unwrap_or_else(|| panic!("no {col} at {t}"))
}

#[test]
fn plcopen_constructs_keep_their_iec_behaviour() {
    let tmp = import("plcopen/all-constructs.xml");
    let dir = tmp.path().join("p");
    // 20 ms scans. Start pressed at 0 for 100 ms; the motor runs; stop at 3000.
    let mut stim = String::from("time_ms,tag,value\n0,Start,1\n100,Start,0\n3000,Stop,1\n3100,Stop,0\n");
    // 24 pulses of the eye (40 ms high, 40 ms low) from 4000 on, then Reset at 7000.
    for i in 0..24 {
        stim.push_str(&format!("{},Eye,1\n{},Eye,0\n", 4000 + i * 80, 4040 + i * 80));
    }
    stim.push_str("7000,Reset,1\n7100,Reset,0\n");
    // Stock: load at 8000 (PV 10), take 10 times, empty after the tenth.
    stim.push_str("8000,Refill,1\n8020,Refill,0\n");
    for i in 0..10 {
        stim.push_str(&format!("{},Take,1\n{},Take,0\n", 8100 + i * 40, 8120 + i * 40));
    }
    // The alarm horn: a 1.5 s pulse, acknowledged at 10000.
    stim.push_str("9000,Alarm,1\n9200,Alarm,0\n");
    let cols = [
        "Motor",
        "Lamp",
        "Elapsed",
        "Fan",
        "StartPulse",
        "Stopped",
        "Count",
        "BatchDone",
        "Empty",
        "Stock.ACC",
        "Horn",
        "HornPulse.DN",
    ];
    let rows = sim(&dir, &stim, &cols, 11_000, 20);
    // Seal-in; the rising-edge contact gives one pulse.
    assert_eq!(at(&rows, 0, "Motor"), "1");
    assert_eq!(at(&rows, 0, "StartPulse"), "1");
    assert_eq!(at(&rows, 20, "StartPulse"), "0");
    assert_eq!(at(&rows, 2000, "Motor"), "1");
    // TON Delay, PT = T#2s: Q after 2 s, ET counts.
    assert_eq!(at(&rows, 1000, "Elapsed"), "1000");
    assert_eq!(at(&rows, 1980, "Lamp"), "0");
    assert_eq!(at(&rows, 2000, "Lamp"), "1");
    // Fan is the negated coil of TOF(NOT Motor): on while the motor runs.
    assert_eq!(at(&rows, 1000, "Fan"), "1");
    // Stop: the motor drops, the F_TRIG pulses once, the lamp goes off.
    assert_eq!(at(&rows, 3000, "Motor"), "0");
    assert_eq!(at(&rows, 3000, "Stopped"), "1");
    assert_eq!(at(&rows, 3020, "Stopped"), "0");
    assert_eq!(at(&rows, 3000, "Lamp"), "0");
    assert_eq!(at(&rows, 3000, "Fan"), "0");
    // 24 eye pulses through R_TRIG into CTU (PV 24): Q at the 24th.
    assert_eq!(at(&rows, 4000, "Count"), "1");
    assert_eq!(at(&rows, 5800, "Count"), "23");
    assert_eq!(at(&rows, 5800, "BatchDone"), "0");
    assert_eq!(at(&rows, 5880, "Count"), "24");
    assert_eq!(at(&rows, 5880, "BatchDone"), "1");
    // R resets CV and Q.
    assert_eq!(at(&rows, 7000, "Count"), "0");
    assert_eq!(at(&rows, 7000, "BatchDone"), "0");
    // CTD: LD loads PV = 10, ten CD edges empty it (Q = CV <= 0).
    assert_eq!(at(&rows, 8000, "Stock.ACC"), "10");
    assert_eq!(at(&rows, 8340, "Stock.ACC"), "3");
    assert_eq!(at(&rows, 8420, "Empty"), "0");
    assert_eq!(at(&rows, 8460, "Stock.ACC"), "0");
    assert_eq!(at(&rows, 8460, "Empty"), "1");
    // TP: a 1.5 s pulse sets the horn; Ack resets it (not in this stimulus: it stays).
    assert_eq!(at(&rows, 9000, "HornPulse.DN"), "1");
    assert_eq!(at(&rows, 10480, "HornPulse.DN"), "1");
    assert_eq!(at(&rows, 10500, "HornPulse.DN"), "0");
    assert_eq!(at(&rows, 10500, "Horn"), "1");
}

#[test]
fn beremiz_orange_light_blinks() {
    let tmp = import("plcopen/beremiz-orange-blink.xml");
    let rows = sim(&tmp.path().join("p"), "time_ms,tag,value\n", &["%QX0.1"], 10_000, 100);
    let v: Vec<&str> = rows
        .iter()
        .map(|(_, m)| m.get("%QX0.1").map(String::as_str).unwrap_or(""))
        .collect();
    // Off 500 ms (TON1 on NOT light), set by R_TRIG1; on 500 ms (TON2),
    // reset by R_TRIG0. With 100 ms scans the light comes on at 500 and goes
    // off at 1000; TON1 runs before the reset in the scan, so it starts one
    // scan later: off 6 scans, on 5, from then on.
    let ons = v.windows(2).filter(|w| w[0] == "0" && w[1] == "1").count();
    assert_eq!(v[..22].join(""), "0000011111000000111110", "{v:?}");
    assert!((8..=10).contains(&ons), "{ons} blinks in 10 s: {v:?}");
}

/// The times (ms) at which `col` changes, after the first row.
fn edges(rows: &[(u64, HashMap<String, String>)], col: &str) -> Vec<u64> {
    rows.windows(2)
        .filter(|w| w[0].1.get(col) != w[1].1.get(col))
        .map(|w| w[1].0)
        .collect()
}

#[test]
fn openplc_blink_makes_the_square_wave_of_its_timers() {
    // OpenPLC Editor's Blink example: TON(IN := NOT blink_led, PT := 500 ms)
    // into TOF(PT := 500 ms), whose Q drives blink_led; 20 ms scans. IEC:
    // the TON's Q rises at 500 and sets the light through the TOF; one scan
    // later the TON's IN falls, the TOF times 500 ms from 520 and the light
    // goes off at 1020; the TON starts again at 1040, and so on.
    let tmp = import("plcopen/openplc-blink.xml");
    let rows = sim(&tmp.path().join("p"), "time_ms,tag,value\n", &["blink_led"], 5_000, 20);
    assert_eq!(at(&rows, 0, "blink_led"), "0");
    assert_eq!(
        edges(&rows, "blink_led"),
        [500, 1020, 1540, 2060, 2580, 3100, 3620, 4140, 4660]
    );
}

#[test]
fn openplc_arduino_cloud_counts_pulses_and_seconds() {
    // The pulse of the Blink timers counted by a CTU reset by its own Q at
    // 60 (through the coil CTU_reset), the count moved to minute_count
    // (%QW0); TON1 times 600 s and TIME_TO_REAL(TON1.ET) is seconds.
    let tmp = import("plcopen/openplc-arduino-cloud.xml");
    let cols = ["oscillator_pulse", "minute_count", "time_lapsed"];
    let rows = sim(&tmp.path().join("p"), "time_ms,tag,value\n", &cols, 70_000, 20);
    let rises: Vec<u64> = edges(&rows, "oscillator_pulse").into_iter().step_by(2).collect();
    assert_eq!(rises[..3], [500, 1540, 2580]);
    // Pulse k (from 1) is counted at its rising edge.
    assert_eq!(at(&rows, rises[0], "minute_count"), "1");
    assert_eq!(at(&rows, rises[1] - 20, "minute_count"), "1");
    assert_eq!(at(&rows, rises[58], "minute_count"), "59");
    // The 60th count sets Q: the next scan resets CV through R.
    assert_eq!(at(&rows, rises[59], "minute_count"), "60");
    assert_eq!(at(&rows, rises[59] + 20, "minute_count"), "0");
    assert_eq!(at(&rows, rises[60], "minute_count"), "1");
    assert_eq!(at(&rows, 12_340, "time_lapsed"), "12.34");
    assert_eq!(at(&rows, 0, "time_lapsed"), "0");
}

#[test]
fn openplc_dnp3test_drives_its_coils() {
    // PB1 on the rail; the negated coil PB2 after PB1 and LED in parallel:
    // PB2 = NOT TRUE; LED on the rail and again after PB2 (a coil passes its
    // input on, negated or not).
    let tmp = import("plcopen/openplc-dnp3test.xml");
    let rows = sim(
        &tmp.path().join("p"),
        "time_ms,tag,value\n",
        &["PB1", "PB2", "LED"],
        200,
        20,
    );
    for (t, _) in &rows {
        assert_eq!(
            [at(&rows, *t, "PB1"), at(&rows, *t, "PB2"), at(&rows, *t, "LED")],
            ["1", "0", "1"]
        );
    }
}

#[test]
fn plcopen_functions_compute() {
    let tmp = import("plcopen/blocks.xml");
    let dir = tmp.path().join("p");
    let stim = "time_ms,tag,value\n0,Level,600\n0,Run,1\n200,Run,0\n300,Level,50\n";
    let rows = sim(
        &dir,
        stim,
        &["Ticks", "Adding", "High", "Low", "Half", "Shown", "Ten"],
        400,
        10,
    );
    // ADD counts while Run (EN) is on: 1 at the first scan, 20 at 190 ms.
    assert_eq!(at(&rows, 0, "Ticks"), "1");
    assert_eq!(at(&rows, 190, "Ticks"), "20");
    assert_eq!(at(&rows, 250, "Ticks"), "20");
    assert_eq!(at(&rows, 0, "Adding"), "1");
    assert_eq!(at(&rows, 200, "Adding"), "0");
    // EQ gated by Run: Ticks = 10 at 90 ms.
    assert_eq!(at(&rows, 90, "Ten"), "1");
    assert_eq!(at(&rows, 100, "Ten"), "0");
    // GT and LE on the analog input.
    assert_eq!(at(&rows, 0, "High"), "1");
    assert_eq!(at(&rows, 0, "Low"), "0");
    assert_eq!(at(&rows, 300, "High"), "0");
    assert_eq!(at(&rows, 300, "Low"), "1");
    // MUL in REAL; MOVE gated by Run keeps the last value when Run is off.
    assert_eq!(at(&rows, 0, "Half"), "300");
    assert_eq!(at(&rows, 300, "Half"), "25");
    assert_eq!(at(&rows, 300, "Shown"), "300");
}

/// A xorshift stimulus: digital inputs given as (name, first value, one
/// change in so many scans on average), and analog inputs given as (name,
/// range) that jump to random values, every `scan` ms for `scans` scans.
fn random_stimulus(seed: u64, bits: &[(&str, u64, u64)], analog: &[(&str, u64)], scans: u64, scan: u64) -> String {
    let mut x = seed;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    let mut stim = String::from("time_ms,tag,value\n");
    let mut last: Vec<u64> = bits.iter().map(|b| b.1).collect();
    for (b, v, _) in bits {
        stim.push_str(&format!("0,{b},{v}\n"));
    }
    for k in 1..scans {
        for (i, (b, _, every)) in bits.iter().enumerate() {
            if next().is_multiple_of(*every) {
                last[i] = 1 - last[i];
                stim.push_str(&format!("{},{b},{}\n", k * scan, last[i]));
            }
        }
        for (a, range) in analog {
            if next().is_multiple_of(13) {
                stim.push_str(&format!("{},{a},{}\n", k * scan, next() % range));
            }
        }
    }
    stim
}

#[test]
fn l5x_belt_conveyor_equals_the_native_program() {
    // A Studio 5000 export (l5x2c's example): the failures are BIT members
    // of a UDT over a SINT that `MOV(-1, …)` sets at once (marker bits over
    // a marker byte in Alba), timers with `?` presets from the tag data and
    // nested output branches. The native program has five BOOL flags.
    let tmp = import("l5x/l5x2c-belt_conveyor.L5X");
    let imported = tmp.path().join("p");
    let native = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/native/belt-conveyor");
    // Start, Rearm and the two feedbacks change every few seconds; the
    // normally closed Stop, Emergency, Overload and Misalignment open for a
    // moment now and then.
    let random = random_stimulus(
        0xD1B5_4A32_D192_ED03,
        &[
            ("Start", 0, 150),
            ("Rearm", 0, 200),
            ("Contactor_Feedback", 0, 60),
            ("Break_Open", 0, 60),
        ],
        &[],
        6000,
        20,
    );
    let mut rows: Vec<(u64, String)> = random
        .lines()
        .skip(1)
        .map(|l| {
            (
                l.split(',').next().and_then(|t| t.parse().ok()).unwrap_or(0),
                l.to_string(),
            )
        })
        .collect();
    for (tag, at) in [("Stop", 0), ("Emergency", 0), ("Overload", 0), ("Misalignment", 0)] {
        rows.push((at, format!("{at},{tag},1")));
    }
    for (k, tag) in ["Emergency", "Overload", "Misalignment", "Stop"]
        .iter()
        .cycle()
        .take(12)
        .enumerate()
    {
        let at = 9_000 + k as u64 * 9_000;
        rows.push((at, format!("{at},{tag},0")));
        rows.push((at + 400, format!("{},{tag},1", at + 400)));
    }
    rows.sort_by_key(|r| r.0);
    let stim = format!(
        "time_ms,tag,value\n{}\n",
        rows.into_iter().map(|r| r.1).collect::<Vec<_>>().join("\n")
    );
    let pairs = [
        ("Started", "Started"),
        ("Horn", "Horn"),
        ("Contactor", "Contactor"),
        ("Open_Break", "Open_Break"),
        ("Failure_Summary", "No_Failure"),
        ("Conveyor_Failures_Contactor_Failure", "Contactor_OK"),
        ("Conveyor_Failures_Break_Jammed", "Brake_OK"),
        ("Conveyor_Failures_Overload", "Overload_OK"),
        ("Conveyor_Failures_Emergency_Stop", "EStop_OK"),
        ("Conveyor_Failures_Misalignment", "Aligned"),
        ("T_Horn.ACC", "T_Horn.ACC"),
        ("T_Contactor_Feedback.ACC", "T_Feedback.ACC"),
    ];
    let a = sim(&imported, &stim, &pairs.map(|p| p.0), 120_000, 20);
    let b = sim(&native, &stim, &pairs.map(|p| p.1), 120_000, 20);
    assert_eq!(a.len(), b.len());
    let mut seen: HashMap<&str, Vec<String>> = HashMap::new();
    for ((t, ra), (_, rb)) in a.iter().zip(&b) {
        for (ia, nb) in pairs {
            assert_eq!(ra.get(ia), rb.get(nb), "{ia} / {nb} at t = {t} ms");
            let v = ra.get(ia).cloned().unwrap_or_default();
            let e = seen.entry(ia).or_default();
            if !e.contains(&v) {
                e.push(v);
            }
        }
    }
    // Every output and failure flag took both values.
    for (ia, _) in &pairs[..10] {
        assert_eq!(seen[ia].len(), 2, "{ia} never changed: {:?}", seen[ia]);
    }
}

#[test]
fn aurora_plant_equals_the_native_program() {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/aurora/planta");
    let tmp = tempfile::tempdir().expect("tmp");
    let imported = tmp.path().join("p");
    alba_import::import(&folder, &imported, &Options::default()).expect("import");
    let native = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/native/aurora-planta");
    // Start, Sensor and Reset change every 2 s or so; Stop (NC) is closed
    // and opens (or closes again) every 10 s or so.
    let stim = random_stimulus(
        0x9E37_79B9_7F4A_7C15,
        &[
            ("DI:1/0", 0, 100),
            ("DI:1/1", 1, 500),
            ("DI:1/2", 0, 20),
            ("DI:1/3", 0, 150),
        ],
        &[("AI:3/0", 1024)],
        3000,
        20,
    );
    let cols = [
        "DO:2/0", "DO:2/1", "DO:2/2", "DO:2/3", "AO:4/0", "Run", "T1.ACC", "T2.DN", "T3.ACC", "T3.DN", "C1.ACC",
        "InBand", "High", "Percent", "Ticks", "Rest", "Neg", "Rad", "Sine", "Dist",
    ];
    let a = sim(&imported, &stim, &cols, 60_000, 20);
    let b = sim(&native, &stim, &cols, 60_000, 20);
    assert_eq!(a.len(), b.len());
    let mut seen: HashMap<&str, Vec<String>> = HashMap::new();
    for ((t, ra), (_, rb)) in a.iter().zip(&b) {
        for c in cols {
            assert_eq!(ra.get(c), rb.get(c), "{c} at t = {t} ms");
            let v = ra.get(c).cloned().unwrap_or_default();
            let e = seen.entry(c).or_default();
            if !e.contains(&v) {
                e.push(v);
            }
        }
    }
    // The stimulus exercises every output both ways, and the counter and
    // the running-time timer reach their presets.
    for c in ["DO:2/0", "DO:2/1", "DO:2/2", "DO:2/3", "InBand", "High", "T3.DN"] {
        assert!(seen[c].len() >= 2, "{c} never changed: {:?}", seen[c]);
    }
    assert!(seen["AO:4/0"].len() > 10, "speed: {:?}", seen["AO:4/0"]);
}

#[test]
fn plcopen_sfc_equals_the_native_chart() {
    let tmp = import("plcopen/sfc-batch.xml");
    let imported = tmp.path().join("p");
    let native = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/native/sfc-batch");
    // Batches: start, the level rises by 50 every 300 ms to 900 (Heat lasts
    // 2.4 s: its L action stops at 2 s), then falls to 0; now and then Stop is pressed while filling A, and Start is held
    // or released at random.
    let mut x: u64 = 0x51_7CC1_B727_220A;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    let mut stim = String::from("time_ms,tag,value\n");
    let mut t = 0u64;
    for batch in 0..12 {
        stim.push_str(&format!("{t},Start,1\n"));
        if batch % 4 == 3 {
            stim.push_str(&format!("{},Stop,1\n{},Stop,0\n", t + 150, t + 400));
        }
        let hold = 200 + next() % 3000;
        stim.push_str(&format!("{},Start,0\n", t + hold));
        for k in 0..=18u64 {
            stim.push_str(&format!("{},Level,{}\n", t + 200 + k * 300, k * 50));
        }
        // Every third batch waits long in Empty (its D action comes on).
        let late = if batch % 3 == 1 { 9000 } else { 0 };
        t += 200 + 18 * 300 + 2000 + late + next() % 3000;
        for k in (0..18u64).rev() {
            t += 100;
            stim.push_str(&format!("{t},Level,{}\n", k * 50));
        }
        t += 500 + next() % 2000;
    }
    let cols = [
        "ValveA",
        "ValveB",
        "Agitator",
        "Drain",
        "Heater",
        "Busy",
        "EndPulse",
        "LeftMix",
        "Aborted",
        "Late",
        "batch.Idle.X",
        "batch.FillA.X",
        "batch.FillB.X",
        "batch.Heat.X",
        "batch.Mix.X",
        "batch.Empty.X",
        "batch.Done.X",
        "batch.Abort.X",
        "batch.Mix.T",
    ];
    let a = sim(&imported, &stim, &cols, t, 10);
    let b = sim(&native, &stim, &cols, t, 10);
    assert_eq!(a.len(), b.len());
    let mut on: HashMap<&str, usize> = HashMap::new();
    for ((tt, ra), (_, rb)) in a.iter().zip(&b) {
        for c in cols {
            assert_eq!(ra.get(c), rb.get(c), "{c} at t = {tt} ms");
            if ra.get(c).map(String::as_str) == Some("1") {
                *on.entry(c).or_default() += 1;
            }
        }
    }
    // Every step and every action was active at some point.
    for c in &cols[..18] {
        assert!(on.get(c).copied().unwrap_or(0) > 0, "{c} never on");
    }
}

#[test]
fn plcopen_counters_and_edges_equal_the_native_program() {
    let tmp = import("plcopen/counters-edges.xml");
    let imported = tmp.path().join("p");
    let native = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/native/plcopen-counters");
    // In2 starts true: IEC's F_TRIG pulses on the first scan when CLK starts
    // false, and Alba's OSF does not (the import reports it).
    let stim = random_stimulus(
        0xD1B5_4A32_D192_ED03,
        &[("%IX0.0", 0, 7), ("%IX0.1", 1, 9), ("%IX0.2", 0, 60), ("%IX0.3", 0, 40)],
        &[],
        6000,
        10,
    );
    let cols = [
        "Full",
        "Empty",
        "Up3",
        "Down0",
        "PartsCV",
        "UDCV",
        "Fell",
        "Pulse4",
        "Drop4",
        "Parts.ACC",
        "Stock.ACC",
    ];
    let a = sim(&imported, &stim, &cols, 60_000, 10);
    let b = sim(&native, &stim, &cols, 60_000, 10);
    assert_eq!(a.len(), b.len());
    let mut seen: HashMap<&str, Vec<String>> = HashMap::new();
    for ((t, ra), (_, rb)) in a.iter().zip(&b) {
        for c in cols {
            assert_eq!(ra.get(c), rb.get(c), "{c} at t = {t} ms");
            let v = ra.get(c).cloned().unwrap_or_default();
            let e = seen.entry(c).or_default();
            if !e.contains(&v) {
                e.push(v);
            }
        }
    }
    for c in ["Full", "Empty", "Up3", "Down0", "Fell", "Pulse4", "Drop4"] {
        assert_eq!(seen[c].len(), 2, "{c} never changed");
    }
    assert!(seen["UDCV"].len() > 4, "UDCV: {:?}", seen["UDCV"]);
    assert!(
        seen["Stock.ACC"].iter().any(|v| v.starts_with('-')),
        "Stock never went below 0"
    );
}

#[test]
fn l5x_analog_channels_carry_their_values() {
    let tmp = import("l5x/analog.L5X");
    let dir = tmp.path().join("p");
    let stim =
        "time_ms,tag,value\n0,AI:3/0,8192\n0,AI:3/1,1234\n0,AI:3/2,777\n0,DI:1/0,1\n100,AI:3/0,20000\n200,DI:1/0,0\n";
    let cols = ["LevelPct", "HighLevel", "AO:4/0", "AO:4/1", "ValveOut"];
    let rows = sim(&dir, stim, &cols, 300, 20);
    // Ch0Data is AI:3/0, Ch1Data AI:3/1, Ch2Data AI:3/2; the outputs AO:4/0 and AO:4/1.
    assert_eq!(at(&rows, 0, "AO:4/1"), "1234");
    assert_eq!(at(&rows, 0, "AO:4/0"), "24575");
    assert_eq!(at(&rows, 0, "HighLevel"), "0");
    assert!(
        at(&rows, 0, "LevelPct").starts_with("25.0"),
        "{}",
        at(&rows, 0, "LevelPct")
    );
    assert_eq!(at(&rows, 100, "HighLevel"), "1");
    assert_eq!(at(&rows, 100, "AO:4/0"), "12767");
    assert_eq!(at(&rows, 200, "AO:4/0"), "777");
    assert_eq!(at(&rows, 200, "ValveOut"), "777");
}

#[test]
fn plcopen_st_program_runs_with_its_iec_behaviour() {
    // st-motor.xml: an ST body (start-stop seal, R_TRIG counting the starts
    // into an INT and an ARRAY, a global limit of 3, TON of 50 ms driving the
    // lamp); 10 ms scans. Start pulses at 0, 300, 500, 700; stop at 200,
    // 400, 600. The fourth start counts to 4 > limit, which stops the motor
    // in the same scan, so the motor never rises at 700.
    let tmp = import("plcopen/st-motor.xml");
    let dir = tmp.path().join("p");
    let mut stim = String::from("time_ms,tag,value\n");
    for t in [0, 300, 500, 700] {
        stim.push_str(&format!("{t},start,1\n{},start,0\n", t + 20));
    }
    for t in [200, 400, 600] {
        stim.push_str(&format!("{t},stop,1\n{},stop,0\n", t + 20));
    }
    let cols = [
        "motor",
        "lamp",
        "main.starts",
        "main.history[0]",
        "main.history[1]",
        "main.history[3]",
    ];
    let rows = sim(&dir, &stim, &cols, 900, 10);
    assert_eq!(at(&rows, 0, "motor"), "1");
    assert_eq!(edges(&rows, "motor"), [200, 300, 400, 500, 600]);
    assert_eq!(edges(&rows, "lamp"), [50, 200, 350, 400, 550, 600]);
    assert_eq!(at(&rows, 650, "main.starts"), "3");
    assert_eq!(at(&rows, 800, "main.starts"), "4");
    assert_eq!(at(&rows, 800, "main.history[1]"), "1");
    assert_eq!(at(&rows, 800, "main.history[3]"), "3");
    assert_eq!(at(&rows, 650, "main.history[0]"), "0");
    assert_eq!(at(&rows, 800, "main.history[0]"), "4");
}

#[test]
fn plcopen_sfc_actions_written_in_st_run_while_their_step_is_active() {
    // sfc-st-actions.xml: Idle (N Close: valve off, level 0) → start →
    // Filling (P1 Count: fills + 1; N Fill: valve on, level + 1) → level >= 5
    // → Idle. Two start pulses: two fills of five scans each.
    let tmp = import("plcopen/sfc-st-actions.xml");
    let stim = "time_ms,tag,value\n0,start,1\n20,start,0\n300,start,1\n320,start,0\n";
    let rows = sim(&tmp.path().join("p"), stim, &["valve", "level", "fills"], 600, 10);
    let on = |from: u64, to: u64| {
        rows.iter()
            .filter(|(t, m)| (from..to).contains(t) && m.get("valve").map(String::as_str) == Some("1"))
            .count()
    };
    assert_eq!(on(0, 300), 5, "{rows:?}");
    assert_eq!(on(300, 600), 5, "{rows:?}");
    let levels: Vec<i64> = rows
        .iter()
        .filter_map(|(_, m)| m.get("level").and_then(|v| v.parse().ok()))
        .collect();
    assert_eq!(levels.iter().max(), Some(&5), "{levels:?}");
    assert_eq!(at(&rows, 250, "fills"), "1");
    assert_eq!(at(&rows, 590, "fills"), "2");
    assert_eq!(at(&rows, 590, "level"), "0");
    assert_eq!(at(&rows, 590, "valve"), "0");
}

#[test]
fn aurora_timers_keep_their_time_base() {
    // planta: T1 a TON of 2 in a 1 s base, T2 a TOF of 15 in a 0.1 s base, T3 an RTO of 5000 ms.
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/aurora/planta");
    let tmp = tempfile::tempdir().expect("tmp");
    let imported = tmp.path().join("p");
    let report = alba_import::import(&folder, &imported, &Options::default()).expect("import");
    let lad = std::fs::read_to_string(imported.join("main.lad")).expect("main.lad");
    for want in ["TON(T1,2,0,s)", "TOF(T2,15,0,ds)", "RTO(T3,5000,0)"] {
        assert!(lad.contains(want), "{want} not in\n{lad}");
    }
    // Kept, not converted: nothing about the bases is approximated.
    let text = format!("{report:?}");
    assert!(!text.contains("time base"), "{text}");
}

/// A trace of an imported project as `alba sim` writes it, in one engine
/// mode (`fused`, `monitored` or `native`).
fn trace_in(mode: &str, dir: &Path, stimulus: &str, cols: &str, until: u64, every: u64) -> String {
    let c = alba_load::compile_dir(dir);
    let mut msg = String::new();
    for d in &c.diagnostics {
        msg.push_str(&d.short(c.files()));
    }
    let scan_ms = c.project.config.as_ref().map(|c| u64::from(c.scan_ms)).expect("config");
    let prog = c
        .program
        .unwrap_or_else(|| panic!("{} does not compile: {msg}", dir.display()));
    let mut files = alba_diag::Files::new();
    let fid = files.add("stimulus.csv", stimulus.to_string());
    let stim = alba_engine::sim::Stimulus::parse(stimulus, fid, &prog.layout)
        .unwrap_or_else(|d| panic!("stimulus: {}", d.iter().map(|d| d.short(&files)).collect::<String>()));
    let columns = alba_engine::sim::columns(cols, &prog.layout).expect("columns");
    let mut engine = alba_engine::Engine::new(Arc::new(prog)).expect("engine");
    match mode {
        "monitored" => engine.set_monitor(true),
        "native" => engine.compile_native().expect("native code"),
        _ => {}
    }
    let mut out = Vec::new();
    let opt = alba_engine::sim::SimOptions {
        scan_ms,
        until_ms: until,
        every_ms: every,
    };
    alba_engine::sim::run(&mut engine, &stim, &columns, opt, &mut out).expect("sim");
    String::from_utf8(out).expect("utf8")
}

/// The PLCopen fixtures with functions, function blocks and SFC actions in ST run with
/// their golden traces (`tests/golden/plcopen-traces/<fixture>.csv`;
/// `ALBA_BLESS=1` rewrites them) in every engine mode.
#[test]
fn plcopen_st_functions_and_function_blocks_run_with_their_golden_traces() {
    let cases: [(&str, &str, &str, u64, u64); 4] = [
        // IronPLC's test project: the FB instance keeps its state (Count,
        // set once by the stimulus) as Main calls it with Reset FALSE.
        (
            "ironplc-simple",
            "time_ms,tag,value\n20,Main.MyCounter.Count,5\n",
            "Main.MyCounter.Reset,Main.MyCounter.Count",
            60,
            10,
        ),
        // Beremiz's first steps: CounterST counts every 100 ms scan, a
        // Reset loads the configuration's constant 17; AverageVal is the
        // mean of the five counts (four stay 0).
        (
            "beremiz-first-steps-st",
            "time_ms,tag,value\n1000,plc_prg.Reset,1\n1200,plc_prg.Reset,0\n",
            "plc_prg.Reset,plc_prg.Cnt1,plc_prg.AVCnt,plc_prg.CounterST0.Cnt",
            2000,
            100,
        ),
        // A start edge fills the tank by 25 a scan to 100 (full), drains it
        // by 50 a scan to 0, counts a cycle; Logger (the lower-priority
        // task, run after Main) logs the cycles in its array.
        (
            "st-pous-types",
            "time_ms,tag,value\n20,start,1\n40,start,0\n200,start,1\n300,start,0\n",
            "start,full,cycles,Main.plant.level,Main.plant.mode,Logger.log[1],Logger.log[2],Logger.last",
            400,
            10,
        ),
        // OpenPLC's SFC test (OpenPLC_v3, matiec's tests): a named ST
        // action and inline ST action bodies (actions `A<block>_<k>`), ST
        // conditions. GO → STEP1 at once (IX1 FALSE); IX2 leads to STEP2,
        // whose P action steps QX1/QX2 through A1, A2, A3 (which write
        // IX1) to the simultaneous D1–D3, E1–E3 and back to GO; IX1 cleared
        // again starts a second round, which waits in D (QX3 stays TRUE).
        (
            "openplc-sfc-test",
            "time_ms,tag,value\n300,IX2,1\n450,IX1,0\n",
            "QX1,QX2,QX3,IX1,IX2,MAIN_TEST.GO.X,MAIN_TEST.STEP1.X,MAIN_TEST.STEP2.X,MAIN_TEST.A1.X,MAIN_TEST.A2.X,MAIN_TEST.A3.X,MAIN_TEST.D1.X,MAIN_TEST.E3.X",
            520,
            10,
        ),
    ];
    let bless = std::env::var_os("ALBA_BLESS").is_some();
    let golden_dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden/plcopen-traces");
    for (fixture, stim, cols, until, every) in cases {
        let tmp = import(&format!("plcopen/{fixture}.xml"));
        let golden = golden_dir.join(format!("{fixture}.csv"));
        let want = std::fs::read_to_string(&golden).unwrap_or_default();
        for mode in ["fused", "monitored", "native"] {
            let got = trace_in(mode, &tmp.path().join("p"), stim, cols, until, every);
            if bless {
                std::fs::create_dir_all(&golden_dir).expect("golden dir");
                std::fs::write(&golden, &got).expect("write golden");
                break;
            }
            assert_eq!(want, got, "{fixture} ({mode}) differs from {}", golden.display());
        }
    }
}

/// STRING, WSTRING and date variables of a PLCopen ST program (as OpenPLC's
/// editor writes them: `<string length="8"/>`, an initial value in quotes)
/// are imported and run in every engine mode.
#[test]
fn plcopen_st_strings_and_dates_import_and_run() {
    let xml = r#"<?xml version="1.0" encoding="utf-8"?>
<project xmlns="http://www.plcopen.org/xml/tc6_0201" xmlns:xhtml="http://www.w3.org/1999/xhtml">
  <types><pous>
    <pou name="Main" pouType="program">
      <interface><localVars>
        <variable name="greet"><type><string length="8"/></type><initialValue><simpleValue value="'hi'"/></initialValue></variable>
        <variable name="msg"><type><string/></type></variable>
        <variable name="w"><type><wstring length="4"/></type></variable>
        <variable name="day"><type><DATE/></type><initialValue><simpleValue value="D#2024-01-31"/></initialValue></variable>
        <variable name="n"><type><INT/></type></variable>
      </localVars></interface>
      <body><ST><xhtml:p><![CDATA[n := n + 1;
msg := CONCAT(greet, ' ', INT_TO_STRING(n), ' ', REAL_TO_STRING(INT_TO_REAL(n) / 4.0));
w := STRING_TO_WSTRING(LEFT(greet, 1));
]]></xhtml:p></ST></body>
    </pou>
  </pous></types>
</project>
"#;
    let tmp = tempfile::tempdir().expect("tmp");
    let file = tmp.path().join("strings.xml");
    std::fs::write(&file, xml).expect("write");
    let dir = tmp.path().join("p");
    alba_import::import(&file, &dir, &Options::default()).expect("import");
    let st = std::fs::read_to_string(dir.join("Main.st")).expect("Main.st");
    for want in [
        "greet : STRING[8] := 'hi';",
        "msg : STRING;",
        "w : WSTRING[4];",
        "day : DATE := D#2024-01-31;",
    ] {
        assert!(st.contains(want), "{want} not in\n{st}");
    }
    // `hi 2 0.5` on the second scan: its length and characters.
    let cols =
        "Main.n,Main.msg.LEN,Main.msg[1],Main.msg[4],Main.msg[6],Main.msg[7],Main.msg[8],Main.w.LEN,Main.w[1],Main.day";
    let want = "time_ms,Main.n,Main.msg.LEN,Main.msg[1],Main.msg[4],Main.msg[6],Main.msg[7],Main.msg[8],Main.w.LEN,Main.w[1],Main.day\n\
                0,1,9,104,49,48,46,50,1,104,1706659200000\n\
                10,2,8,104,50,48,46,53,1,104,1706659200000\n";
    for mode in ["fused", "monitored", "native"] {
        assert_eq!(
            trace_in(mode, &dir, "time_ms,tag,value\n", cols, 10, 10),
            want,
            "{mode}"
        );
    }
}

/// A configuration's global of one of the file's types (an enumeration, as
/// an OpenPLC oven controller has it) is a file-level VAR_GLOBAL of ST that
/// the programs' externalVars name; it runs in every engine mode.
#[test]
fn plcopen_globals_of_the_files_types_are_st_globals() {
    let xml = r#"<?xml version="1.0" encoding="utf-8"?>
<project xmlns="http://www.plcopen.org/xml/tc6_0201" xmlns:xhtml="http://www.w3.org/1999/xhtml">
  <types>
    <dataTypes>
      <dataType name="Mode_t"><baseType><enum><values><value name="stopped"/><value name="running"/><value name="done"/></values></enum></baseType></dataType>
    </dataTypes>
    <pous>
      <pou name="main" pouType="program">
        <interface>
          <externalVars><variable name="mode"><type><derived name="Mode_t"/></type></variable></externalVars>
          <externalVars constant="true"><variable name="last"><type><derived name="Mode_t"/></type></variable></externalVars>
          <localVars><variable name="n"><type><INT/></type></variable></localVars>
        </interface>
        <body><ST><xhtml:p><![CDATA[n := n + 1;
IF mode = stopped THEN mode := running; ELSIF n >= 3 THEN mode := last; END_IF;]]></xhtml:p></ST></body>
      </pou>
    </pous>
  </types>
  <instances><configurations><configuration name="Config0">
    <resource name="Res0"><task name="t" priority="0" interval="T#10ms"><pouInstance name="i" typeName="main"/></task></resource>
    <globalVars><variable name="mode"><type><derived name="Mode_t"/></type><initialValue><simpleValue value="stopped"/></initialValue></variable></globalVars>
    <globalVars constant="true"><variable name="last"><type><derived name="Mode_t"/></type><initialValue><simpleValue value="done"/></initialValue></variable></globalVars>
  </configuration></configurations></instances>
</project>
"#;
    let tmp = tempfile::tempdir().expect("tmp");
    let file = tmp.path().join("oven.xml");
    std::fs::write(&file, xml).expect("write");
    let dir = tmp.path().join("p");
    let report = alba_import::import(&file, &dir, &Options::default()).expect("import");
    let text = report.render();
    assert!(!text.contains("refused"), "{text}");
    let g = std::fs::read_to_string(dir.join("globals.st")).expect("globals.st");
    assert_eq!(
        g,
        "VAR_GLOBAL\n    mode : Mode_t := stopped;\nEND_VAR\nVAR_GLOBAL CONSTANT\n    last : Mode_t := done;\nEND_VAR\n"
    );
    let want = "time_ms,mode,main.n\n0,1,1\n10,1,2\n20,2,3\n";
    for mode in ["fused", "monitored", "native"] {
        assert_eq!(
            trace_in(mode, &dir, "time_ms,tag,value\n", "mode,main.n", 20, 10),
            want,
            "{mode}"
        );
    }
    // Exported, globals.st becomes the resource's globalVars lists (CONSTANT kept), and
    // imported again it is the same file and the same run.
    let (xml, report) = alba_import::export_plcopen(&dir).expect("export");
    assert_eq!(report.count(alba_import::Kind::Refused), 0, "{}", report.render());
    assert!(xml.contains("<globalVars constant=\"true\">"), "{xml}");
    let again = tmp.path().join("again.xml");
    std::fs::write(&again, &xml).expect("write");
    let second = tmp.path().join("second");
    let r = alba_import::import(&again, &second, &Options::default()).expect("import again");
    assert_eq!(r.count(alba_import::Kind::Refused), 0, "{}", r.render());
    assert_eq!(
        std::fs::read_to_string(second.join("globals.st")).expect("globals.st"),
        g
    );
    assert_eq!(
        trace_in("fused", &second, "time_ms,tag,value\n", "mode,main.n", 20, 10),
        want
    );
}
