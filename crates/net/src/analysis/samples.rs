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
