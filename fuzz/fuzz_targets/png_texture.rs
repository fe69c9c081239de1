//! The PNG texture reader on arbitrary bytes: a typed error or an image whose pixel buffer
//! matches its size, never a panic or an unbounded allocation.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(img) = wavg::apps::Image::decode_png(std::io::Cursor::new(data)) {
        assert!(img.width > 0 && img.height > 0);
    }
});
