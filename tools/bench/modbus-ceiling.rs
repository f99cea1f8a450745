//! The fastest Modbus TCP "server" this machine can run: a blocking thread
//! per connection that answers every 12-byte FC3 request for 10 registers
//! with a fixed 29-byte reply (transaction id echoed), nothing else — no
//! parsing, no memory, no engine. `alba bench --modbus --target` against it
//! measures the ceiling that the load client and the kernel's loopback set
//! on this machine (docs/performance.md, "The Modbus TCP server under load").
//!
//!     rustc -O tools/bench/modbus-ceiling.rs -o target/modbus-ceiling
//!     target/modbus-ceiling 127.0.0.1:5020 &
//!     target/release/alba bench --modbus --target 127.0.0.1:5020

use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};

fn serve(mut s: TcpStream) {
    let _ = s.set_nodelay(true);
    let mut req = [0u8; 12];
    let mut reply = [0u8; 29];
    reply[5] = 23;
    reply[6] = 1;
    reply[7] = 3;
    reply[8] = 20;
    while s.read_exact(&mut req).is_ok() {
        reply[0] = req[0];
        reply[1] = req[1];
        if s.write_all(&reply).is_err() {
            return;
        }
    }
}

fn main() {
    let addr = std::env::args().nth(1).unwrap_or_else(|| "127.0.0.1:5020".into());
    let l = TcpListener::bind(&addr).expect("bind");
    for s in l.incoming().flatten() {
        std::thread::spawn(move || serve(s));
    }
}
