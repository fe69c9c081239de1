//! The point, weight and `.npy` readers on arbitrary bytes: a typed error or rows that
//! survive a write/read round trip, never a panic or an allocation beyond the input.
#![no_main]

use libfuzzer_sys::fuzz_target;
use wavg::text::{LineChunks, PointSpec, parse_points, parse_weights, push_numbers};

fuzz_target!(|data: &[u8]| {
    // Text, streamed in small chunks: every chunk either parses or names a line inside it.
    let mut chunks = LineChunks::new(data, 3);
    while let Ok(Some(chunk)) = chunks.next_chunk() {
        let lines = chunk.text.lines().count();
        let in_chunk = |line: usize| line >= chunk.first_line && line < chunk.first_line + lines;
        match parse_weights(&chunk.text, chunk.first_line) {
            Ok(rows) => {
                for (line, row) in rows {
                    assert!(in_chunk(line));
                    let mut text = Vec::new();
                    push_numbers(&mut text, row.iter().copied());
                    let back = parse_weights(std::str::from_utf8(&text).unwrap(), 1).unwrap();
                    let back = back.first().map(|(_, r)| r.clone()).unwrap_or_default();
                    assert_eq!(back, row, "numbers round-trip through their text");
                }
            }
            Err(e) => assert!(in_chunk(e.line)),
        }
        match parse_points(&chunk.text, chunk.first_line) {
            Ok(points) => {
                for (line, p) in points {
                    assert!(in_chunk(line));
                    if let PointSpec::Face { bary, .. } = p {
                        assert!(bary.iter().all(|b| b.is_finite()));
                    }
                }
            }
            Err(e) => assert!(in_chunk(e.line)),
        }
    }
    // NumPy: rows streamed in blocks and the whole-array reader agree (memory grows with
    // the data present, whatever the header declares).
    let whole = wavg::npy::read_matrix(data);
    if let Ok(mut r) = wavg::npy::NpyReader::new(data) {
        let mut rows = Vec::new();
        let streamed = loop {
            match r.read_rows(&mut rows, 1 << 10) {
                Ok(0) => break true,
                Ok(_) if r.cols() == 0 => break true,
                Ok(_) => {}
                Err(_) => break false,
            }
        };
        if let (true, Ok((_, _, values))) = (streamed, &whole) {
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&rows), bits(values));
        }
    }
});
