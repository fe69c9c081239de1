//! A 3x5 pixel font for the digits and signs of numbers (the colour legend's labels).

/// Glyph rows (top first, 3 bits each, most significant bit on the left) for `c`, or
/// `None` for characters the font lacks.
fn glyph(c: char) -> Option<[u8; 5]> {
    Some(match c {
        '0' => [0b111, 0b101, 0b101, 0b101, 0b111],
        '1' => [0b010, 0b110, 0b010, 0b010, 0b111],
        '2' => [0b111, 0b001, 0b111, 0b100, 0b111],
        '3' => [0b111, 0b001, 0b111, 0b001, 0b111],
        '4' => [0b101, 0b101, 0b111, 0b001, 0b001],
        '5' => [0b111, 0b100, 0b111, 0b001, 0b111],
        '6' => [0b111, 0b100, 0b111, 0b101, 0b111],
        '7' => [0b111, 0b001, 0b010, 0b010, 0b010],
        '8' => [0b111, 0b101, 0b111, 0b101, 0b111],
        '9' => [0b111, 0b101, 0b111, 0b001, 0b111],
        '.' => [0b000, 0b000, 0b000, 0b000, 0b010],
        '-' => [0b000, 0b000, 0b111, 0b000, 0b000],
        '+' => [0b000, 0b010, 0b111, 0b010, 0b000],
        'e' => [0b000, 0b111, 0b111, 0b100, 0b111],
        ' ' => [0; 5],
        _ => return None,
    })
}

/// Calls `plot(x, y)` for every lit pixel of `text` drawn at (`x0`, `y0`) (top left) with
/// square pixels of `scale`; characters the font lacks are skipped. Returns the width drawn.
pub(super) fn draw_text(
    text: &str,
    x0: i64,
    y0: i64,
    scale: i64,
    mut plot: impl FnMut(i64, i64),
) -> i64 {
    let mut x = x0;
    for c in text.chars() {
        let Some(rows) = glyph(c) else { continue };
        for (r, bits) in rows.iter().enumerate() {
            for col in 0..3 {
                if bits & (0b100 >> col) != 0 {
                    for dy in 0..scale {
                        for dx in 0..scale {
                            plot(x + col * scale + dx, y0 + r as i64 * scale + dy);
                        }
                    }
                }
            }
        }
        x += 4 * scale;
    }
    x - x0
}

/// A short label for a legend: 4 significant digits, scientific notation outside
/// [1e-3, 1e5).
pub(super) fn label(v: f64) -> String {
    let a = v.abs();
    if a != 0.0 && !(1e-3..1e5).contains(&a) {
        format!("{v:.2e}")
    } else {
        let s = format!("{v:.4}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s.is_empty() || s == "-" {
            "0".into()
        } else {
            s.into()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_are_short() {
        assert_eq!(label(0.0), "0");
        assert_eq!(label(1.5), "1.5");
        assert_eq!(label(-2.0), "-2");
        assert_eq!(label(123456.0), "1.23e5");
    }

    #[test]
    fn digits_light_pixels_inside_their_cell() {
        let mut n = 0;
        let w = draw_text("8", 10, 20, 2, |x, y| {
            assert!((10..16).contains(&x) && (20..30).contains(&y));
            n += 1;
        });
        assert_eq!(w, 8);
        assert_eq!(n, 13 * 4);
    }
}
