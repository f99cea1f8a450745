//! Generated nets for benchmarks and tests.

use crate::PtNet;

/// `k` independent cycles of `n` places each, one token per cycle: `n^k` states.
pub fn cycles(k: usize, n: usize) -> PtNet {
    let mut net = PtNet::new();
    for c in 0..k {
        let first = net.places.len();
        for i in 0..n {
            net.add_place(&format!("c{c}p{i}"), u32::from(i == 0));
        }
        for i in 0..n {
            let t = net.add_transition(&format!("c{c}t{i}"));
            net.add_pre(t, first + i, 1);
            net.add_post(t, first + (i + 1) % n, 1);
        }
    }
    net
}

/// `n` dining philosophers, each taking the left fork then the right one (deadlock when
/// every philosopher holds the left fork). Places per philosopher: `think`, `hasL`, `eat`,
/// `fork`; transitions `takeL`, `takeR`, `release`.
pub fn philosophers(n: usize) -> PtNet {
    let mut net = PtNet::new();
    let mut think = Vec::new();
    let mut has_l = Vec::new();
    let mut eat = Vec::new();
    let mut fork = Vec::new();
    for i in 0..n {
        think.push(net.add_place(&format!("think{i}"), 1));
        has_l.push(net.add_place(&format!("hasL{i}"), 0));
        eat.push(net.add_place(&format!("eat{i}"), 0));
        fork.push(net.add_place(&format!("fork{i}"), 1));
    }
    for i in 0..n {
        let right = (i + 1) % n;
        let t = net.add_transition(&format!("takeL{i}"));
        net.add_pre(t, think[i], 1);
        net.add_pre(t, fork[i], 1);
        net.add_post(t, has_l[i], 1);
        let t = net.add_transition(&format!("takeR{i}"));
        net.add_pre(t, has_l[i], 1);
        net.add_pre(t, fork[right], 1);
        net.add_post(t, eat[i], 1);
        let t = net.add_transition(&format!("release{i}"));
        net.add_pre(t, eat[i], 1);
        net.add_post(t, think[i], 1);
        net.add_post(t, fork[i], 1);
        net.add_post(t, fork[right], 1);
    }
    net
}

/// The Kanban system of Ciardo and Tilgner (the Model Checking Contest's
/// `Kanban`): four machines with `n` kanbans each, 16 places and 16
/// transitions. Machine i: `P{i}` (free kanbans, `n` at start), `Pm{i}` (a
/// part being machined), `Pback{i}` (sent back for rework), `Pout{i}` (done).
/// Machine 1 feeds machines 2 and 3 together (`tsynch1_23`), which feed
/// machine 4 together (`tsynch4_23`). Reachable markings: 160 for n = 1,
/// 4 600 for 2, 58 400 for 3, 454 475 for 4, 2 546 432 for 5.
pub fn kanban(n: u32) -> PtNet {
    let mut net = PtNet::new();
    let mut p = Vec::new();
    for i in 1..=4 {
        let free = net.add_place(&format!("P{i}"), n);
        let m = net.add_place(&format!("Pm{i}"), 0);
        let back = net.add_place(&format!("Pback{i}"), 0);
        let out = net.add_place(&format!("Pout{i}"), 0);
        p.push((free, m, back, out));
    }
    let arcs = |net: &mut PtNet, id: &str, pre: &[usize], post: &[usize]| {
        let t = net.add_transition(id);
        for &x in pre {
            net.add_pre(t, x, 1);
        }
        for &x in post {
            net.add_post(t, x, 1);
        }
    };
    arcs(&mut net, "tin1", &[p[0].0], &[p[0].1]);
    for (i, &(_, m, back, out)) in p.iter().enumerate() {
        let i = i + 1;
        arcs(&mut net, &format!("tredo{i}"), &[m], &[back]);
        arcs(&mut net, &format!("tback{i}"), &[back], &[m]);
        arcs(&mut net, &format!("tok{i}"), &[m], &[out]);
    }
    arcs(
        &mut net,
        "tsynch1_23",
        &[p[0].3, p[1].0, p[2].0],
        &[p[0].0, p[1].1, p[2].1],
    );
    arcs(
        &mut net,
        "tsynch4_23",
        &[p[1].3, p[2].3, p[3].0],
        &[p[1].0, p[2].0, p[3].1],
    );
    arcs(&mut net, "tout4", &[p[3].3], &[p[3].0]);
    net
}

/// A ring of `stages` places, one token, and `width` parallel transitions from each place
/// to the next: `stages` states but `width^stages` minimal T-invariants (one transition
/// per stage), so the Farkas algorithm runs out of any budget while the flows' basis
/// (`stages·width - stages + 1` T-flows) stays polynomial.
pub fn parallel_ring(stages: usize, width: usize) -> PtNet {
    let mut net = PtNet::new();
    for i in 0..stages {
        net.add_place(&format!("p{i}"), u32::from(i == 0));
    }
    for i in 0..stages {
        for k in 0..width {
            let t = net.add_transition(&format!("t{i}_{k}"));
            net.add_pre(t, i, 1);
            net.add_post(t, (i + 1) % stages, 1);
        }
    }
    net
}
