//! Splitting lines into tokens and reading lines of numbers in one pass over their bytes:
//! the hot loop of reading large weight files. Both give exactly what the general path
//! (`split_whitespace` before a `#`, then `str::parse` per token) gives; the number scanner
//! declines any line it is not sure of, and the caller then takes the general path, which
//! also words the errors.

/// Byte classes of ASCII text: part of a token, whitespace (what `char::is_whitespace`
/// accepts in ASCII: space, tab, line feed, vertical tab, form feed, carriage return) or
/// the start of a comment. Bytes of non-ASCII characters count as token bytes.
const TOKEN: u8 = 0;
const SPACE: u8 = 1;
const COMMENT: u8 = 2;
const CLASS: [u8; 256] = {
    let mut c = [TOKEN; 256];
    c[b' ' as usize] = SPACE;
    c[b'\t' as usize] = SPACE;
    c[b'\n' as usize] = SPACE;
    c[0x0B] = SPACE;
    c[0x0C] = SPACE;
    c[b'\r' as usize] = SPACE;
    c[b'#' as usize] = COMMENT;
    c
};

/// The whitespace-separated tokens of `line` before any `#`, into `out`: the same as
/// `split_whitespace` on the text before the `#`, in one pass over the bytes when the
/// line is ASCII (Unicode whitespace is only possible otherwise).
pub(super) fn tokens<'a>(line: &'a str, out: &mut Vec<&'a str>) {
    out.clear();
    if !line.is_ascii() {
        let l = line.split_once('#').map_or(line, |(a, _)| a);
        out.extend(l.split_whitespace());
        return;
    }
    let b = line.as_bytes();
    let mut i = skip_space(b, 0);
    while i < b.len() && b[i] != b'#' {
        let start = i;
        while i < b.len() && CLASS[b[i] as usize] == TOKEN {
            i += 1;
        }
        // Both ends are ASCII bytes of the line, so on character boundaries.
        out.push(&line[start..i]);
        i = skip_space(b, i);
    }
}

/// The finite numbers of a line of whitespace-separated numbers (before any `#`), into
/// `out`, read straight from the bytes. Returns `false`, with `out` in any state, when the
/// line has anything else (a token that is not a finite number, non-ASCII whitespace):
/// the caller then reads the line token by token.
pub(super) fn numbers(line: &str, out: &mut Vec<f64>) -> bool {
    out.clear();
    let b = line.as_bytes();
    let mut i = skip_space(b, 0);
    while i < b.len() && b[i] != b'#' {
        let Ok((x, n)) = fast_float2::parse_partial::<f64, _>(&b[i..]) else {
            return false;
        };
        i += n;
        // The number must be the whole token, and finite.
        if !x.is_finite() || (i < b.len() && CLASS[b[i] as usize] == TOKEN) {
            return false;
        }
        out.push(x);
        i = skip_space(b, i);
    }
    true
}

/// The first position at or after `i` that is not ASCII whitespace.
fn skip_space(b: &[u8], mut i: usize) -> usize {
    while i < b.len() && CLASS[b[i] as usize] == SPACE {
        i += 1;
    }
    i
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The general path: tokens before the comment, each parsed by `str::parse` and
    /// required finite.
    fn general(line: &str) -> Option<Vec<f64>> {
        let before = line.split_once('#').map_or(line, |(a, _)| a);
        before
            .split_whitespace()
            .map(|t| t.parse::<f64>().ok().filter(|x| x.is_finite()))
            .collect()
    }

    fn pieces() -> impl Strategy<Value = String> {
        proptest::collection::vec(
            prop_oneof![
                Just(" "),
                Just("\t"),
                Just("\r"),
                Just("\u{b}"),
                Just("\u{c}"),
                Just("\u{a0}"),
                Just("\u{3000}"),
                Just("#"),
                Just("x"),
                Just("é"),
                Just("0"),
                Just("7"),
                Just("."),
                Just("e"),
                Just("E"),
                Just("+"),
                Just("-"),
                Just("inf"),
                Just("nan"),
                Just("1.5"),
                Just("-2e-3"),
                Just("1e400"),
            ],
            0..24,
        )
        .prop_map(|p| p.concat())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(4096))]

        /// The byte tokenizer splits exactly as `split_whitespace` before the first `#`,
        /// for ASCII and non-ASCII lines alike.
        #[test]
        fn tokens_are_split_whitespace_before_the_comment(line in pieces()) {
            let mut got = Vec::new();
            tokens(&line, &mut got);
            let before = line.split_once('#').map_or(line.as_str(), |(a, _)| a);
            let want: Vec<&str> = before.split_whitespace().collect();
            prop_assert_eq!(got, want);
        }

        /// Whatever the number scanner accepts, the general path reads to the same bits.
        #[test]
        fn scanned_numbers_are_the_general_paths(line in pieces()) {
            let mut got = Vec::new();
            if numbers(&line, &mut got) {
                let want = general(&line);
                prop_assert!(want.is_some(), "{line:?} accepted, general path rejects it");
                let want = want.unwrap();
                prop_assert_eq!(got.len(), want.len());
                for (a, b) in got.iter().zip(&want) {
                    prop_assert_eq!(a.to_bits(), b.to_bits());
                }
            }
        }

        /// Lines as the library writes them, and other common spellings, take the fast
        /// path and read back exactly.
        #[test]
        fn written_numbers_take_the_fast_path(
            bits in proptest::collection::vec(any::<u64>(), 1..12),
            scale in -30i32..30,
        ) {
            let xs: Vec<f64> = bits
                .iter()
                .map(|b| f64::from_bits(*b))
                .filter(|x| x.is_finite())
                .map(|x| x * 10f64.powi(scale))
                .filter(|x| x.is_finite())
                .collect();
            let mut line = Vec::new();
            crate::text::push_numbers(&mut line, xs.iter().copied());
            let mut text = String::from_utf8(line).unwrap();
            text.push_str(" +1.5 .25 3. 1E2 # note");
            let mut got = Vec::new();
            prop_assert!(numbers(&text, &mut got), "declined {text:?}");
            let mut want = xs.clone();
            want.extend([1.5, 0.25, 3.0, 100.0]);
            prop_assert_eq!(got.len(), want.len());
            for (a, b) in got.iter().zip(&want) {
                prop_assert_eq!(a.to_bits(), b.to_bits());
            }
        }
    }
}
