//! What `hydrocyl simulate` writes for a value: a command file's unit
//! converted on the decimal (the times and commands written back are the
//! numbers given, in SI), and no subnormal or `-0.0` (tester t38d C3).

mod common;

use common::simulate_ok;

/// A command file in [ms] and [%] is converted on the decimal: the output's
/// `time [s]` and `command [-]` are the numbers written, in SI (`1.999` ms
/// is `0.001999`, not `0.0019990000000000003`; 7 % is `0.07`), on the
/// whole-file and the streamed reader alike (tester t38d C3).
#[test]
fn millisecond_and_percent_commands_are_written_as_the_decimals_given() {
    let dir = tempfile::tempdir().unwrap();
    let cmd = dir.path().join("ms.csv");
    let mut s = String::from("time [ms],command [%]\n");
    let mut want = Vec::new();
    for k in 0..3000 {
        let (t, u) = (format!("{:.3}", k as f64 * 0.001), (k / 100) % 15);
        s.push_str(&format!("{t},{u}\n"));
        // the decimal text moved by 3 (2) places, as a file in s (-) gives
        want.push((
            format!("{t}e-3").parse::<f64>().unwrap(),
            format!("{u}e-2").parse::<f64>().unwrap(),
        ));
    }
    std::fs::write(&cmd, s).unwrap();
    for extra in [&[][..], &["--stream-above", "100"][..]] {
        let out = dir.path().join("out.csv");
        simulate_ok("leaney-moog", &cmd, &out, &[&["--quiet"], extra].concat());
        let text = std::fs::read_to_string(&out).unwrap();
        for (line, (t, u)) in text.lines().skip(1).zip(&want) {
            let mut cells = line.split(',');
            let (tc, uc) = (cells.next().unwrap(), cells.next().unwrap());
            let bits = |c: &str| c.parse::<f64>().unwrap().to_bits();
            assert_eq!(
                (bits(tc), bits(uc)),
                (t.to_bits(), u.to_bits()),
                "{extra:?}: {line}"
            );
        }
        assert!(text.contains("\n0.001999,"), "{extra:?}");
    }
}

/// A pressure decaying onto the tank's 0 Pa (the valve saturated, the
/// piston on its stop) is written as 0.0, not as a subnormal such as
/// `-1.3e-316`; and no cell is `-0.0` (tester t38d C3).
#[test]
fn no_subnormal_or_negative_zero_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let cmd = dir.path().join("sat.csv");
    let rows: String = (0..2001)
        .map(|k| format!("{},5\n", k as f64 * 1e-3))
        .collect();
    std::fs::write(&cmd, format!("time,command\n{rows}")).unwrap();
    let out = dir.path().join("out.csv");
    simulate_ok("leaney-moog", &cmd, &out, &["--quiet"]);
    let text = std::fs::read_to_string(&out).unwrap();
    let mut zeros = 0;
    for line in text.lines().skip(1) {
        for cell in line.split(',') {
            let v: f64 = cell.parse().unwrap();
            assert!(!v.is_subnormal(), "{cell} in `{line}`");
            assert!(!cell.starts_with("-0.0") || v != 0.0, "{cell} in `{line}`");
            zeros += usize::from(v == 0.0);
        }
    }
    assert!(zeros > 0);
}
