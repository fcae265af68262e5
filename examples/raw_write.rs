//! The speed limit for writing a city: `cargo run --release --example raw_write -- BYTES FILE`
//! writes BYTES of OBJ vertex lines (`v x y z`, millimetres as fixed-point metres with an
//! integer formatter, the fastest formatting we know) into FILE in 1 MiB chunks, and prints the
//! seconds it took. `make bench` compares the build's own formatting and writing against it.

use std::io::Write;
use std::time::Instant;

fn push_mm(buf: &mut Vec<u8>, v: i64, itoa_buf: &mut itoa::Buffer) {
    if v < 0 {
        buf.push(b'-');
    }
    let a = v.unsigned_abs();
    buf.extend_from_slice(itoa_buf.format(a / 1000).as_bytes());
    buf.push(b'.');
    let frac = a % 1000;
    if frac < 100 {
        buf.push(b'0');
    }
    if frac < 10 {
        buf.push(b'0');
    }
    buf.extend_from_slice(itoa_buf.format(frac).as_bytes());
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (Some(bytes), Some(path)) = (args.get(1).and_then(|b| b.parse::<u64>().ok()), args.get(2))
    else {
        eprintln!("usage: raw_write BYTES FILE");
        std::process::exit(2);
    };
    let start = Instant::now();
    let mut file = std::fs::File::create(path).expect("output file");
    let mut buf = Vec::with_capacity(1 << 21);
    let mut itoa_buf = itoa::Buffer::new();
    let (mut written, mut i) = (0u64, 0i64);
    while written < bytes {
        // Coordinates of the size a city has: hundreds of metres, millimetres.
        let (x, y, z) = (
            123_456 + i % 250_000,
            2_000 + i % 9_000,
            -(87_654 + i % 250_000),
        );
        buf.extend_from_slice(b"v ");
        push_mm(&mut buf, x, &mut itoa_buf);
        buf.push(b' ');
        push_mm(&mut buf, y, &mut itoa_buf);
        buf.push(b' ');
        push_mm(&mut buf, z, &mut itoa_buf);
        buf.push(b'\n');
        i += 7;
        if buf.len() >= 1 << 20 {
            file.write_all(&buf).expect("write");
            written += buf.len() as u64;
            buf.clear();
        }
    }
    file.write_all(&buf).expect("write");
    file.flush().expect("flush");
    drop(file);
    let secs = start.elapsed().as_secs_f64();
    println!("{secs:.3}");
}
