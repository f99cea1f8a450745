//! What the Arduino crate's tests share: a small deterministic random
//! generator and random ladder programs over the aurora map's I/O.
#![allow(dead_code)]

/// xorshift64*: deterministic, seeded.
pub struct Rng(pub u64);
impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    pub fn below(&mut self, n: u64) -> u64 {
        self.next() % n.max(1)
    }
}

/// The tags.csv and main.lad of a random ladder program over the aurora map's I/O: contacts in series and
/// parallel branches, coils, latches, one-shots, every timer and counter,
/// integer and REAL math and compares on the analog inputs, analog outputs.
pub fn random_ladder(seed: u64) -> (String, String) {
    let mut r = Rng(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1);
    let mut tags = String::from("name,type,address,initial,retain,description\n");
    for k in 0..6 {
        tags += &format!("I{k},BOOL,DI:1/{k},,,\nQ{k},BOOL,DO:2/{k},,,\nM{k},BOOL,,,,\n");
    }
    tags += "A0,INT,AI:3/0,,,\nA1,INT,AI:3/1,,,\nP0,INT,AO:4/0,,,\nP1,INT,AO:4/1,,,\n";
    for k in 0..3 {
        tags += &format!("T{k},TIMER,,,,\nC{k},COUNTER,,,,\nN{k},DINT,,,,\nR{k},REAL,,,,\nS{k},BOOL,,,,\n");
    }
    let bits = [
        "I0", "I1", "I2", "I3", "I4", "I5", "Q0", "Q1", "Q2", "M0", "M1", "M2", "M3", "T0.DN", "T1.DN", "T2.TT",
        "C0.DN", "C1.DN", "T0.EN",
    ];
    let outs = ["Q0", "Q1", "Q2", "Q3", "Q4", "Q5", "M0", "M1", "M2", "M3", "M4", "M5"];
    let nums = ["A0", "A1", "N0", "N1", "N2", "T0.ACC", "C0.ACC", "C1.ACC"];
    let reals = ["R0", "R1", "R2"];
    let pick = |r: &mut Rng, xs: &[&'static str]| xs[r.below(xs.len() as u64) as usize];
    let contact = |r: &mut Rng| {
        let b = pick(r, &bits);
        match r.below(10) {
            0..=4 => format!("XIC({b})"),
            5..=7 => format!("XIO({b})"),
            8 => format!("GRT({},{})", pick(r, &nums), r.below(1024)),
            _ => format!("LES({},{}.{})", pick(r, &reals), r.below(500), r.below(10)),
        }
    };
    let mut rungs = String::new();
    let n = 6 + r.below(14);
    for k in 0..n {
        let mut cond = String::new();
        for _ in 0..r.below(3) + 1 {
            if r.below(4) == 0 {
                cond += &format!("[{},{}{}]", contact(&mut r), contact(&mut r), contact(&mut r));
            } else {
                cond += &contact(&mut r);
            }
        }
        let o = pick(&mut r, &outs);
        let t = k % 3;
        let out = match r.below(16) {
            0..=3 => format!("OTE({o})"),
            4 => format!("OTL({o})"),
            5 => format!("OTU({o})"),
            6 => format!("ONS(S{t})OTE({o})"),
            7 | 15 => {
                // T0 counts ms (TP too), T1 centiseconds, T2 deciseconds (one base per timer).
                let kinds: &[&str] = if t == 0 {
                    &["TON", "TOF", "RTO", "TP"]
                } else {
                    &["TON", "TOF", "RTO"]
                };
                let base = ["", ",cs", ",ds"][t as usize];
                kinds[r.below(kinds.len() as u64) as usize].to_string()
                    + &format!("(T{t},{},0{base})", 10 * (1 + r.below(60)) + 5 * r.below(2))
            }
            8 => format!("{}(C{t},{},0)", ["CTU", "CTD"][r.below(2) as usize], r.below(6)),
            9 => format!("RES({}{t})", ["T", "C"][r.below(2) as usize]),
            10 => format!("ADD({},{},N{t})", pick(&mut r, &nums), pick(&mut r, &nums)),
            11 => format!(
                "CPT(R{t},{}*0.37+{}/{}.5)",
                pick(&mut r, &nums),
                pick(&mut r, &reals),
                1 + r.below(9)
            ),
            12 => format!("MOV({},P{})", pick(&mut r, &nums), t % 2),
            13 => format!("DIV({},{},N{t})", pick(&mut r, &nums), pick(&mut r, &nums)),
            14 => format!("SCP(A{},0,1023,0.0,300.0,R{t})", t % 2),
            _ => format!("MUL({},{},N{t})", pick(&mut r, &nums), 1 + r.below(5000)),
        };
        rungs += &format!("{cond}{out};\n");
    }
    // Internal state made visible on the pins.
    rungs += "XIC(T0.DN)OTE(Q3);\nXIC(T1.DN)XIO(T2.DN)OTE(Q4);\n[XIC(C0.DN),XIC(M4)]XIC(C1.OV)OTE(Q5);\n";
    rungs += "DIV(T0.ACC,3,P0);\nMOD(N1,251,P1);\nGRT(R1,N2)OTE(Q2);\n";
    (tags, rungs)
}
