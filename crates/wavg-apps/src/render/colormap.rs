//! The viridis colour map (perceptually uniform, readable in grey and by colour-blind
//! viewers): eleven stops of matplotlib's table, linearly interpolated.

/// Viridis at t = 0, 0.1, ..., 1.
const STOPS: [[u8; 3]; 11] = [
    [0x44, 0x01, 0x54],
    [0x48, 0x24, 0x75],
    [0x41, 0x44, 0x87],
    [0x35, 0x5f, 0x8d],
    [0x2a, 0x78, 0x8e],
    [0x21, 0x91, 0x8c],
    [0x22, 0xa8, 0x84],
    [0x44, 0xbf, 0x70],
    [0x7a, 0xd1, 0x51],
    [0xbd, 0xdf, 0x26],
    [0xfd, 0xe7, 0x25],
];

/// Viridis at `t` (clamped to [0, 1]; NaN maps to 0), as RGB in [0, 255].
pub fn viridis(t: f64) -> [f64; 3] {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let s = t * (STOPS.len() - 1) as f64;
    let i = (s.floor() as usize).min(STOPS.len() - 2);
    let f = s - i as f64;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    [0, 1, 2].map(|k| a[k] as f64 * (1.0 - f) + b[k] as f64 * f)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn endpoints_are_dark_purple_and_yellow() {
        assert_eq!(viridis(0.0), [68.0, 1.0, 84.0]);
        assert_eq!(viridis(1.0), [253.0, 231.0, 37.0]);
        assert_eq!(viridis(-3.0), viridis(0.0));
        assert_eq!(viridis(7.0), viridis(1.0));
        assert_eq!(viridis(f64::NAN), viridis(0.0));
    }

    #[test]
    fn lightness_increases_monotonically() {
        let lum = |c: [f64; 3]| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
        let mut last = -1.0;
        for i in 0..=100 {
            let l = lum(viridis(i as f64 / 100.0));
            assert!(l > last, "not monotone at {i}");
            last = l;
        }
    }
}
