//! CPU seconds used so far by xtask and the children it has waited for (cargo, rustc,
//! pytest, ...), read from `/proc/self/stat`, so that the step table shows where the CPU
//! of a run goes: on a fresh 2-core machine the run is compile-bound, and wall time under
//! load says little.

/// Clock ticks per second of `/proc/self/stat`'s times (Linux's `USER_HZ`, fixed at 100 in
/// its ABI on every architecture the project builds on).
const USER_HZ: f64 = 100.0;

/// A reading of the CPU used so far; `None` where `/proc` is missing (not Linux).
pub fn now() -> Option<f64> {
    std::fs::read_to_string("/proc/self/stat")
        .ok()
        .and_then(|stat| parse_stat(&stat))
}

/// The CPU between two readings, `None` when either is missing.
pub fn between(start: Option<f64>, end: Option<f64>) -> Option<f64> {
    Some((end? - start?).max(0.0))
}

/// User and system time of the process and of its waited-for children (`utime`, `stime`,
/// `cutime`, `cstime`: fields 14-17 of `proc(5)`), in seconds. The command name (field 2)
/// is in parentheses and may hold spaces and parentheses, so fields are counted after the
/// last `)`.
fn parse_stat(stat: &str) -> Option<f64> {
    let rest = &stat[stat.rfind(')')? + 1..];
    // After the name, field 3 (the state) is the first.
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = (14..=17)
        .map(|field| fields.get(field - 3)?.parse::<u64>().ok())
        .sum::<Option<u64>>()?;
    Some(ticks as f64 / USER_HZ)
}

/// A table cell: the seconds, or `-` when unknown.
pub fn cell(secs: Option<f64>) -> String {
    secs.map_or_else(|| "-".to_string(), |s| format!("{s:.1}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_four_times_are_summed_after_the_command_name() {
        // utime 150, stime 50, cutime 1000, cstime 300 ticks; a name with ") 9 9 (".
        let stat = "3048 (x) 9 9 (y) R 3042 3042 28324 0 -1 4194304 101 0 0 0 150 50 1000 300 \
                    20 0 1 0 5724991 3133440 390";
        assert_eq!(parse_stat(stat), Some(15.0));
        assert_eq!(parse_stat("3048 (cat) R 1 2"), None);
        assert_eq!(parse_stat("no name"), None);
    }

    #[test]
    fn a_waited_for_child_s_cpu_is_counted() {
        let before = now().expect("/proc/self/stat");
        let status = std::process::Command::new("sh")
            .args(["-c", "i=0; while [ $i -lt 300000 ]; do i=$((i+1)); done"])
            .status()
            .unwrap();
        assert!(status.success());
        let used = between(Some(before), now()).unwrap();
        assert!(used >= 0.1, "the child's loop took {used} CPU s");
    }

    #[test]
    fn unknown_readings_give_a_dash() {
        assert_eq!(between(None, Some(1.0)), None);
        assert_eq!(between(Some(2.0), Some(1.0)), Some(0.0));
        assert_eq!(cell(None), "-");
        assert_eq!(cell(Some(12.345)), "12.3");
    }
}
