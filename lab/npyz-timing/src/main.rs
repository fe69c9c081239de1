//! wavg-io's `.npy` code against the `npyz` crate: with no argument, the time to write and
//! to stream-read 10^6 x 8 float64 with each (best of 5, alternating); with an argument,
//! one hostile header (`hostile-len-*`: a 4 GiB header length, `hostile-shape-*`: a
//! `(2^40, 2^40)` shape, `hostile-big-npyz`: a `(10^11, 3)` shape over 40 bytes) read by
//! `ours` or `npyz` (run under `ulimit -v 1000000` to see an allocation abort).

#![allow(dead_code)]
#[path = "../../../crates/wavg-io/src/npy.rs"]
mod npy;

use npyz::WriterBuilder;
use std::time::Instant;

const ROWS: usize = 1_000_000;
const COLS: usize = 8;

fn ours_write(data: &[f64]) -> Vec<u8> {
    let mut w = npy::NpyWriter::new(Vec::with_capacity(8 * data.len() + 128), ROWS, COLS).unwrap();
    w.write_rows(data).unwrap();
    w.finish().unwrap()
}

fn npyz_write(data: &[f64]) -> Vec<u8> {
    let mut out = Vec::with_capacity(8 * data.len() + 128);
    {
        let mut w = npyz::WriteOptions::new()
            .default_dtype()
            .shape(&[ROWS as u64, COLS as u64])
            .writer(&mut out)
            .begin_nd()
            .unwrap();
        w.extend(data.iter().copied()).unwrap();
        w.finish().unwrap();
    }
    out
}

/// Streams blocks of 65 536 rows, as the command line does.
fn ours_read(bytes: &[u8]) -> f64 {
    let mut r = npy::NpyReader::new(bytes).unwrap();
    let mut buf = Vec::new();
    let mut sum = 0.0;
    while r.read_rows_over(&mut buf, 1 << 16).unwrap() > 0 {
        sum += buf[0];
    }
    sum
}

fn npyz_read(bytes: &[u8]) -> f64 {
    let f = npyz::NpyFile::new(bytes).unwrap();
    let mut it = f.data::<f64>().unwrap();
    let mut buf = Vec::with_capacity((1 << 16) * COLS);
    let mut sum = 0.0;
    loop {
        buf.clear();
        for v in it.by_ref().take((1 << 16) * COLS) {
            buf.push(v.unwrap());
        }
        if buf.is_empty() {
            break;
        }
        sum += buf[0];
    }
    sum
}

/// Milliseconds one call of `f` takes.
fn best(f: &mut dyn FnMut()) -> f64 {
    let t = Instant::now();
    f();
    t.elapsed().as_secs_f64() * 1e3
}

fn main() {
    let arg = std::env::args().nth(1).unwrap_or_default();
    match arg.as_str() {
        "hostile-len-ours" | "hostile-len-npyz" => {
            // Version 2: a 4-byte header length of 0xFFFFFFF0 with 40 bytes behind it.
            let mut bytes = b"\x93NUMPY\x02\x00".to_vec();
            bytes.extend(0xFFFF_FFF0u32.to_le_bytes());
            bytes.extend([b' '; 40]);
            if arg.ends_with("ours") {
                println!("ours: {:?}", npy::read_matrix(&bytes[..]).map(|_| ()));
            } else {
                println!("npyz: {:?}", npyz::NpyFile::new(&bytes[..]).map(|_| ()));
            }
        }
        "hostile-shape-ours" | "hostile-shape-npyz" => {
            let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
            let dict = "{'descr': '<f8', 'fortran_order': False, 'shape': (1099511627776, 1099511627776), }\n";
            bytes.extend((dict.len() as u16).to_le_bytes());
            bytes.extend(dict.as_bytes());
            bytes.extend([0u8; 40]);
            if arg.ends_with("ours") {
                println!("ours: {:?}", npy::read_matrix(&bytes[..]).map(|_| ()));
            } else {
                let r = npyz::NpyFile::new(&bytes[..]).map(|f| f.len());
                println!("npyz: {r:?}");
            }
        }
        "hostile-big-npyz" => {
            // (1e11, 3) with 40 bytes: npyz's own whole-array reader.
            let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
            let dict = "{'descr': '<f8', 'fortran_order': False, 'shape': (100000000000, 3), }\n";
            bytes.extend((dict.len() as u16).to_le_bytes());
            bytes.extend(dict.as_bytes());
            bytes.extend([0u8; 40]);
            let f = npyz::NpyFile::new(&bytes[..]).unwrap();
            println!("npyz into_vec: {:?}", f.into_vec::<f64>().map(|v| v.len()));
        }
        _ => {
            let data: Vec<f64> = (0..ROWS * COLS).map(|i| (i as f64 * 0.37).sin()).collect();
            let a = ours_write(&data);
            let b = npyz_write(&data);
            assert_eq!(ours_read(&a), npyz_read(&b));
            assert_eq!(
                npy::read_matrix(&b[..]).unwrap().2,
                data,
                "npyz's file reads back"
            );
            let (mut w_ours, mut w_npyz, mut r_ours, mut r_npyz) =
                (f64::MAX, f64::MAX, f64::MAX, f64::MAX);
            for _ in 0..5 {
                w_ours = w_ours.min(best(&mut || {
                    std::hint::black_box(ours_write(&data));
                }));
                w_npyz = w_npyz.min(best(&mut || {
                    std::hint::black_box(npyz_write(&data));
                }));
                r_ours = r_ours.min(best(&mut || {
                    std::hint::black_box(ours_read(&a));
                }));
                r_npyz = r_npyz.min(best(&mut || {
                    std::hint::black_box(npyz_read(&b));
                }));
            }
            println!(
                "10^6 x 8 f64 (64 MB), best of 5, ms: write ours {w_ours:.1} npyz {w_npyz:.1}; read ours {r_ours:.1} npyz {r_npyz:.1}"
            );
        }
    }
}
