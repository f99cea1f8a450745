//! scratch profiling harness
use alba_diag::Files;
use alba_engine::Engine;
use std::sync::Arc;

fn preset(i: usize) -> i32 {
    5 + (i % 7) as i32
}

fn generate(n: usize) -> (String, String) {
    let mut tags = String::from("name,type,address,initial,retain,description\n");
    let mut lad = String::new();
    for i in 0..n {
        let a = u8::from(i % 11 == 0);
        tags.push_str(&format!(
            "A_{i},BOOL,,{a},,\nT_{i},TIMER,,,,\nC_{i},COUNTER,,,,\nL_{i},DINT,,{},,\nV_{i},DINT,,,,\nQ_{i},BOOL,,,,\n",
            i % 5
        ));
        lad.push_str(&format!(
            "[XIO(T_{i}.DN),XIC(A_{i})]TON(T_{i},{},0)CTU(C_{i},1000000,0)GRT(C_{i}.ACC,L_{i})ADD(V_{i},1,V_{i})OTE(Q_{i});\n",
            preset(i)
        ));
    }
    (tags, lad)
}

mod native {
    #[derive(Clone, Default)]
    pub struct Rung {
        pub a: bool,
        pub t_pre: i32,
        pub t_acc: i32,
        pub t_last: u32,
        pub t_en: bool,
        pub t_tt: bool,
        pub t_dn: bool,
        pub c_pre: i32,
        pub c_acc: i32,
        pub c_cu: bool,
        pub c_dn: bool,
        pub c_ov: bool,
        pub l: i32,
        pub v: i32,
        pub q: bool,
        pub overflow: bool,
    }
    #[inline(always)]
    fn scan_rung(r: &mut Rung, now: u32) {
        let rc = !r.t_dn || r.a;
        if rc {
            if !r.t_en {
                r.t_en = true;
                r.t_acc = 0;
                r.t_last = now;
            } else if !r.t_dn {
                let dt = now.wrapping_sub(r.t_last);
                r.t_last = now;
                r.t_acc = r.t_acc.saturating_add(dt as i32);
            }
            if !r.t_dn && r.t_acc >= r.t_pre {
                r.t_dn = true;
                r.t_acc = r.t_pre;
            }
            r.t_tt = !r.t_dn;
        } else {
            r.t_en = false;
            r.t_tt = false;
            r.t_dn = false;
            r.t_acc = 0;
        }
        if rc && !r.c_cu {
            match r.c_acc.checked_add(1) {
                Some(v) => r.c_acc = v,
                None => {
                    r.c_acc = i32::MIN;
                    r.c_ov = true;
                }
            }
        }
        r.c_cu = rc;
        r.c_dn = r.c_acc >= r.c_pre;
        let rc = rc && r.c_acc > r.l;
        if rc {
            match r.v.checked_add(1) {
                Some(v) => r.v = v,
                None => {
                    r.v = r.v.wrapping_add(1);
                    r.overflow = true;
                }
            }
        }
        r.q = rc;
    }
    #[inline(never)]
    pub fn scan(rungs: &mut [Rung], now: u32) {
        for r in rungs.iter_mut() {
            scan_rung(r, now);
        }
    }
}
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mode = args[1].as_str();
    let n: usize = args[2].parse().unwrap();
    let scans: u64 = args[3].parse().unwrap();
    if mode == "rust" {
        let mut rs: Vec<native::Rung> = (0..n)
            .map(|i| native::Rung {
                a: i % 11 == 0,
                t_pre: preset(i),
                c_pre: 1_000_000,
                l: (i % 5) as i32,
                ..Default::default()
            })
            .collect();
        let t = std::time::Instant::now();
        for k in 0..scans {
            native::scan(std::hint::black_box(&mut rs), std::hint::black_box(k as u32));
        }
        println!(
            "{:.2} ns/rung",
            t.elapsed().as_nanos() as f64 / (scans * n as u64) as f64
        );
        return;
    }
    let upd: u32 = std::env::var("UPD").ok().and_then(|u| u.parse().ok()).unwrap_or(1);
    let (tags_csv, lad) = if mode.starts_with("pid") {
        let mut tags = String::from("name,type,address,initial,retain,description\n");
        let mut lad = String::new();
        for i in 0..n {
            tags.push_str(&format!(
                "L_{i},PID,,\"KP=1.5;KI=0.4;KD=0.1;UPD={upd};SP=50\",,\nPV_{i},REAL,,{},,\nCV_{i},REAL,,,,\n",
                (i % 97) as f32
            ));
            lad.push_str(&format!("PID(L_{i},PV_{i},CV_{i});\n"));
        }
        (tags, lad)
    } else if mode.starts_with("shuf") {
        let (tags, lad) = generate(n);
        let lines: Vec<&str> = tags.lines().skip(1).collect();
        let len = lines.len();
        let mut out = String::from("name,type,address,initial,retain,description\n");
        let mut seen = vec![false; len];
        let mut k = 0usize;
        for _ in 0..len {
            while seen[k] {
                k = (k + 1) % len;
            }
            seen[k] = true;
            out.push_str(lines[k]);
            out.push('\n');
            k = (k * 7919 + 13) % len;
        }
        (out, lad)
    } else {
        generate(n)
    };
    let mode = mode.trim_start_matches("pid").trim_start_matches("shuf");
    let mut files = Files::new();
    let tf = files.add("tags.csv", tags_csv);
    let lf = files.add("main.lad", lad);
    let (tags, _) = alba_model::TagTable::parse(files.text(tf), tf);
    let (ast, _) = alba_ladder::parse(files.text(lf), lf);
    let layout = alba_ladder::layout_for(&tags, &[&ast]);
    let mut b = alba_ir::Builder::new(layout);
    let src = files.text(lf).to_string();
    let _ = alba_ladder::compile(&ast, &src, "main.lad", &mut b, &mut alba_ladder::Presets::default());
    let p = Arc::new(b.finish(files));
    if mode == "sizes" {
        println!(
            "Op {} X {} Loc {} ops {} fast {}",
            std::mem::size_of::<alba_ir::Op>(),
            std::mem::size_of::<alba_engine::exec::X>(),
            std::mem::size_of::<alba_ir::Loc>(),
            p.ops.len(),
            alba_engine::exec::Code::new(&p, true).ops.len()
        );
        return;
    }
    if mode == "dump" {
        print!("{}", p.dump());
        return;
    }
    let mut e = Engine::new(p).unwrap();
    if mode == "both" {
        let mut rs: Vec<native::Rung> = (0..n)
            .map(|i| native::Rung {
                a: i % 11 == 0,
                t_pre: preset(i),
                c_pre: 1_000_000,
                l: (i % 5) as i32,
                ..Default::default()
            })
            .collect();
        let mut e2 = Engine::new(e.shared_program()).unwrap();
        e.compile_native().unwrap();
        let (mut k1, mut k2, mut k3) = (0u64, 0u64, 0u64);
        let mut ratios = Vec::new();
        let mut ir = Vec::new();
        let (mut tr, mut tn, mut ti) = (Vec::new(), Vec::new(), Vec::new());
        for round in 0..21 {
            let t = std::time::Instant::now();
            for _ in 0..scans {
                native::scan(std::hint::black_box(&mut rs), std::hint::black_box(k1 as u32));
                k1 += 1;
            }
            let a = t.elapsed().as_nanos() as f64;
            let t = std::time::Instant::now();
            for _ in 0..scans {
                e.scan(std::hint::black_box(k2)).unwrap();
                k2 += 1;
            }
            let b = t.elapsed().as_nanos() as f64;
            let t = std::time::Instant::now();
            for _ in 0..scans {
                e2.scan(std::hint::black_box(k3)).unwrap();
                k3 += 1;
            }
            let c = t.elapsed().as_nanos() as f64;
            if round > 0 {
                ratios.push(b / a);
                ir.push(c / a);
                tr.push(a);
                tn.push(b);
                ti.push(c);
            }
        }
        let med = |mut v: Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        let per = (scans * n as u64) as f64;
        let min = |v: &Vec<f64>| v.iter().copied().fold(f64::INFINITY, f64::min);
        println!(
            "n={n}: min rust {:.2} native {:.2} interp {:.2}",
            min(&tr) / per,
            min(&tn) / per,
            min(&ti) / per
        );
        println!(
            "n={n}: rust {:.2} native {:.2} interp {:.2} ns/rung; native/rust {:.2} interp/rust {:.2}",
            med(tr) / per,
            med(tn) / per,
            med(ti) / per,
            med(ratios),
            med(ir)
        );
        return;
    }
    if mode == "listing" {
        print!("{}", e.native_listing().unwrap());
        return;
    }
    if mode == "native" {
        e.compile_native().unwrap();
    }
    let t = std::time::Instant::now();
    for k in 0..scans {
        e.scan(std::hint::black_box(k)).unwrap();
    }
    println!(
        "{:.2} ns/rung",
        t.elapsed().as_nanos() as f64 / (scans * n as u64) as f64
    );
    println!(
        "footprint {} B/rung layout {:?}",
        e.footprint() as f64 / n as f64,
        e.native_layout()
    );
}
