//! `hydrocyl xfactor` end to end: output format, precision, errors.

use std::process::{Command, Output};

fn hydrocyl(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hydrocyl"))
        .args(args)
        .output()
        .expect("the hydrocyl binary runs")
}

#[test]
fn prints_one_round_trippable_line_per_travel() {
    let g = 11.43 / 5.8;
    let gs = format!("{g:?}");
    let out = hydrocyl(&[
        "xfactor",
        "--gamma",
        &gs,
        "--travel",
        "-1.5,-1,-0.2,0,0.3,1,2",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 7, "{text}");
    for (line, t) in lines.iter().zip([-1.5, -1.0, -0.2, 0.0, 0.3, 1.0, 2.0]) {
        let mut it = line.split(' ');
        let tp: f64 = it.next().unwrap().parse().unwrap();
        let x: f64 = it.next().unwrap().parse().unwrap();
        assert!(it.next().is_none(), "{line}");
        assert_eq!(tp, t);
        // bit-exact: the printed value parses back to the library's value
        assert_eq!(x, hydrocyl_xfactor::x_factor(g, t), "{line}");
    }
}

#[test]
fn brent_option_agrees() {
    let out = hydrocyl(&[
        "xfactor", "--gamma", "2.5", "--travel", "-0.4,0.4", "--brent", "--tol", "1e-13",
    ]);
    assert!(out.status.success());
    for line in String::from_utf8(out.stdout).unwrap().lines() {
        let v: Vec<f64> = line.split(' ').map(|s| s.parse().unwrap()).collect();
        let exact = hydrocyl_xfactor::x_factor(2.5, v[0]);
        assert!((v[1] - exact).abs() < 1e-12, "{line}");
    }
}

#[test]
fn bad_numbers_are_one_line_errors_with_exit_code_2() {
    let cases: [(&[&str], &str); 5] = [
        (
            &["xfactor", "--gamma", "2", "--travel", "0.1,abc"],
            "item 2",
        ),
        (&["xfactor", "--gamma", "x", "--travel", "0"], "--gamma"),
        (&["xfactor", "--gamma", "0.5", "--travel", "0"], "gamma"),
        (&["xfactor", "--gamma", "2", "--travel", "NaN"], "NaN"),
        (
            &[
                "xfactor", "--gamma", "2", "--travel", "0", "--brent", "--tol", "-1",
            ],
            "tolerance",
        ),
    ];
    for (args, needle) in cases {
        let out = hydrocyl(args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(out.stdout.is_empty(), "{args:?}: no partial output");
        let err = String::from_utf8(out.stderr).unwrap();
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
    }
}
