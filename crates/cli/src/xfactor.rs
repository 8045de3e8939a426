//! `hydrocyl xfactor`: Leaney's X factor for an area ratio and a list of
//! normalised spool travels, one `travel X` line per travel, at full
//! (round-trippable) precision so that other tools can check it.
//!
//! ```text
//! $ hydrocyl xfactor --gamma 4 --travel -1,0,1
//! -1.0 16.0
//! 0.0 <X at the null spool position>
//! 1.0 1.0
//! ```

use crate::error::CliError;

/// Arguments of `hydrocyl xfactor`.
#[derive(clap::Args)]
pub struct Args {
    /// Cylinder area ratio gamma = A1/A2 (piston side over rod side), >= 1.
    #[arg(long, allow_hyphen_values = true)]
    gamma: String,
    /// Comma-separated spool travels, each spool position / underlap
    /// (-1 .. 1 is inside the underlap; beyond it X is 1 or gamma^2).
    #[arg(long, allow_hyphen_values = true)]
    travel: String,
    /// Solve eq 3.4 with Brent's method instead of the analytical root.
    #[arg(long)]
    brent: bool,
    /// Absolute tolerance on X for --brent (default 1e-12).
    #[arg(long, allow_hyphen_values = true, requires = "brent")]
    tol: Option<String>,
}

/// Parses one number, naming the argument and the item on failure.
fn parse_number(what: &str, item: usize, text: &str) -> Result<f64, CliError> {
    let s = text.trim();
    let v: f64 = s.parse().map_err(|_| {
        CliError::Input(format!(
            "{what}: item {item} {s:?} is not a number (expected e.g. -0.25)"
        ))
    })?;
    if v.is_nan() {
        return Err(CliError::Input(format!(
            "{what}: item {item} is NaN, which is not a travel or area ratio"
        )));
    }
    Ok(v)
}

/// Runs `hydrocyl xfactor`: validates everything first, then prints.
pub fn run(args: Args) -> Result<(), CliError> {
    let gamma = parse_number("--gamma", 1, &args.gamma)?;
    let travels = args
        .travel
        .split(',')
        .enumerate()
        .map(|(i, t)| parse_number("--travel", i + 1, t))
        .collect::<Result<Vec<f64>, CliError>>()?;
    let tol = match &args.tol {
        Some(text) => parse_number("--tol", 1, text)?,
        None => 1e-12,
    };
    let mut lines = String::new();
    for &t in &travels {
        let x = if args.brent {
            hydrocyl_xfactor::x_factor_numerical_checked(gamma, t, tol)
        } else {
            hydrocyl_xfactor::x_factor_checked(gamma, t)
        }
        .map_err(|e| CliError::Input(format!("xfactor: {e}")))?;
        if !x.is_finite() {
            return Err(CliError::Input(format!(
                "--gamma {} --travel {t}: X is not finite (gamma^2 overflows the arithmetic; area ratios of real cylinders are 1 to about 10)",
                args.gamma.trim()
            )));
        }
        lines.push_str(&format!("{t:?} {x:?}\n"));
    }
    crate::console::print(&lines)
}
