//! The client rules of docs/security.md, "Modbus": the allow-list (a
//! client outside it is disconnected before any request is answered), the
//! read-only option (every write function code answers exception 01 and
//! nothing is written) and the listen rule (loopback, or an allow-list).
//!
//! Linux routes all of 127.0.0.0/8 to loopback, so a client socket bound
//! to 127.0.0.2 is another client address on the same machine.

use crate::{ask, closed, regs, start};
use alba_modbus::check_listen;
use alba_modbus_proto::mbap;
use alba_settings::IpRange;
use std::net::SocketAddr;
use std::sync::atomic::Ordering;
use tokio::io::AsyncWriteExt;
use tokio::net::{TcpSocket, TcpStream};

fn ranges(list: &[&str]) -> Option<Vec<IpRange>> {
    Some(list.iter().map(|r| IpRange::parse(r).expect("a range")).collect())
}

/// A connection to `server` from the local address `from`.
async fn connect_from(from: &str, server: SocketAddr) -> TcpStream {
    let sock = TcpSocket::new_v4().expect("socket");
    let local: SocketAddr = format!("{from}:0").parse().expect("an address");
    sock.bind(local).expect("bind the client to its address");
    sock.connect(server).await.expect("connect")
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_client_outside_the_allow_list_is_closed_unanswered() {
    let f = start("allow", |s| s.allow = ranges(&["127.0.0.1"])).await;
    // From 127.0.0.2: a write (holding register 1 = %QW1 = Valve) is sent,
    // and the connection is closed without an answer.
    let mut s = connect_from("127.0.0.2", f.addr).await;
    let _ = s
        .write_all(&mbap::adu(
            mbap::Header {
                transaction: 1,
                unit: 1,
            },
            &[6, 0, 1, 0, 42],
        ))
        .await;
    assert!(closed(&mut s).await, "a client outside the allow-list was served");
    assert_eq!(f.server.counters.denied.load(Ordering::Relaxed), 1);
    assert_eq!(f.server.counters.requests.load(Ordering::Relaxed), 0);
    // From 127.0.0.1: served, and the refused write did not happen.
    let mut s = connect_from("127.0.0.1", f.addr).await;
    assert_eq!(regs(&ask(&mut s, &[3, 0, 1, 0, 1]).await), [0]);
    assert_eq!(ask(&mut s, &[6, 0, 1, 0, 7]).await, [6, 0, 1, 0, 7]);
    assert_eq!(f.server.counters.denied.load(Ordering::Relaxed), 1);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_allow_list_of_ranges_serves_the_clients_inside() {
    let f = start("allow-range", |s| s.allow = ranges(&["127.0.0.2/31", "::1"])).await;
    for from in ["127.0.0.2", "127.0.0.3"] {
        let mut s = connect_from(from, f.addr).await;
        assert_eq!(regs(&ask(&mut s, &[3, 0, 0, 0, 1]).await), [0], "from {from}");
    }
    let mut s = connect_from("127.0.0.1", f.addr).await;
    assert!(closed(&mut s).await);
    assert_eq!(f.server.counters.denied.load(Ordering::Relaxed), 1);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn read_only_refuses_every_write_and_serves_reads() {
    let f = start("read-only", |s| s.read_only = true).await;
    let h = f.runtime.as_ref().expect("runtime").handle();
    let snap = h.snapshot();
    let place = |n: &str| match snap.program.layout.resolve(n).expect("a tag") {
        alba_ir::Target::Value { place, .. } => place,
        t => panic!("{t:?}"),
    };
    let tags = ["Lamp", "Valve", "Big", "Word", "Ratio", "Speed", "Flag"];
    let before: Vec<_> = tags.iter().map(|t| snap.read(place(t))).collect();
    let mut s = TcpStream::connect(f.addr).await.expect("connect");
    let writes: [&[u8]; 8] = [
        &[5, 0, 9, 0xFF, 0],                     // Lamp
        &[6, 0, 1, 0, 42],                       // Valve
        &[15, 0, 8, 0, 2, 1, 0b11],              // Lamp and its neighbour
        &[16, 0x04, 0x02, 0, 1, 2, 0x12, 0x34],  // Word
        &[16, 0x20, 0x00, 0, 2, 4, 0, 0, 0, 9],  // Speed (explicit address)
        &[5, 0x20, 0x00, 0xFF, 0],               // Flag (explicit address)
        &[23, 0, 0, 0, 1, 0, 1, 0, 1, 2, 0, 42], // read/write: refused whole
        &[22, 0, 1, 0xFF, 0xFF, 0, 0],           // mask write (not implemented anyway)
    ];
    for w in writes {
        assert_eq!(ask(&mut s, w).await, [w[0] | 0x80, 1], "function {}", w[0]);
    }
    // Modbus-only storage (hr 4096, %ML's range) is not written either.
    assert_eq!(ask(&mut s, &[6, 0x10, 0x00, 0xAB, 0xCD]).await, [0x86, 1]);
    assert_eq!(regs(&ask(&mut s, &[3, 0x10, 0x00, 0, 1]).await), [0]);
    // Reads are served: coils, discrete inputs, input and holding registers.
    assert_eq!(ask(&mut s, &[1, 0, 8, 0, 2]).await, [1, 1, 0]);
    assert_eq!(ask(&mut s, &[2, 0, 0, 0, 1]).await, [2, 1, 0]);
    assert_eq!(regs(&ask(&mut s, &[4, 0, 0, 0, 3]).await), [0, 0, 0]);
    assert_eq!(regs(&ask(&mut s, &[3, 0, 1, 0, 1]).await), [0]);
    // Nothing was written, in the runtime's memory either.
    let snap = h.snapshot();
    let after: Vec<_> = tags.iter().map(|t| snap.read(place(t))).collect();
    assert_eq!(before, after);
    assert_eq!(f.server.counters.exceptions.load(Ordering::Relaxed), 9);
}

#[test]
fn beyond_loopback_only_with_an_allow_list() {
    let a = |s: &str| s.parse::<SocketAddr>().expect("an address");
    for ok in ["127.0.0.1:502", "127.0.0.2:0", "[::1]:502", "[::ffff:127.0.0.1]:502"] {
        assert!(check_listen(a(ok), None).is_ok(), "{ok}");
    }
    for bad in ["0.0.0.0:0", "192.168.1.5:502", "[::]:502"] {
        let e = check_listen(a(bad), None).expect_err(bad).to_string();
        assert!(
            e.starts_with(&format!(
                "refusing to serve Modbus TCP on {}: Modbus has no authentication",
                a(bad)
            )),
            "{e}"
        );
        assert!(e.contains("allow = ["), "{e}");
        assert!(
            check_listen(a(bad), ranges(&["10.0.0.0/24"]).as_deref()).is_ok(),
            "{bad}"
        );
    }
}
