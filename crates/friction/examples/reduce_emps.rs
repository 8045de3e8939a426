//! Reduces the EMPS benchmark record (Janot, Gautier, Brunot 2019;
//! `../shared/data/emps_friction_benchmark/DATA_EMPS.csv`, 1 kHz) to the
//! fixture `fixtures/measured/emps-inverse-model.csv`: velocity and
//! acceleration of the prismatic axis by smoothed central differences of the
//! measured position, and the motor force, decimated to 100 Hz.
//!
//! v_i = (q_{i+5} − q_{i−5}) / (10 Δt), a_i = (v_{i+5} − v_{i−5}) / (10 Δt)
//! (each a 10 ms window, a low-pass that keeps the 1–2 Hz motion and
//! suppresses the encoder quantisation), then every 10th sample.
//!
//! ```sh
//! cargo run -p hydrocyl-friction --example reduce_emps -- \
//!     ../shared/data/emps_friction_benchmark/DATA_EMPS.csv fixtures/measured/emps-inverse-model.csv
//! ```
//!
//! Written to a temporary file and renamed into place.

use std::fmt::Write as _;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let [_, src, dst] = args.as_slice() else {
        eprintln!("usage: reduce_emps <DATA_EMPS.csv> <output csv>");
        std::process::exit(2);
    };
    let text = match std::fs::read_to_string(src) {
        Ok(t) => t,
        Err(e) => {
            eprintln!("error: cannot read {src}: {e}");
            std::process::exit(2);
        }
    };
    let mut t = Vec::new();
    let mut q = Vec::new();
    let mut f = Vec::new();
    for (i, line) in text.lines().enumerate().skip(1) {
        let cols: Vec<f64> = line
            .split(',')
            .map(|c| c.trim().parse::<f64>().unwrap_or(f64::NAN))
            .collect();
        if cols.len() != 5 || cols.iter().any(|c| !c.is_finite()) {
            eprintln!("error: {src}, line {}: expected 5 numbers", i + 1);
            std::process::exit(2);
        }
        t.push(cols[0]);
        q.push(cols[1]);
        f.push(cols[4]);
    }
    let n = q.len();
    let w = 5;
    let mut v = vec![f64::NAN; n];
    for i in w..n.saturating_sub(w) {
        v[i] = (q[i + w] - q[i - w]) / (t[i + w] - t[i - w]);
    }
    let mut a = vec![f64::NAN; n];
    for i in 2 * w..n.saturating_sub(2 * w) {
        a[i] = (v[i + w] - v[i - w]) / (t[i + w] - t[i - w]);
    }
    let mut csv = String::from("t_s,velocity_m_per_s,acceleration_m_per_s2,force_n\n");
    for i in (2 * w..n.saturating_sub(2 * w)).step_by(10) {
        let _ = writeln!(csv, "{:.4},{:.6e},{:.6e},{:.5}", t[i], v[i], a[i], f[i]);
    }
    let tmp = format!("{dst}.tmp");
    if let Err(e) = std::fs::write(&tmp, csv).and_then(|_| std::fs::rename(&tmp, dst)) {
        let _ = std::fs::remove_file(&tmp);
        eprintln!("error: cannot write {dst}: {e}");
        std::process::exit(2);
    }
    println!("wrote {dst}");
}
