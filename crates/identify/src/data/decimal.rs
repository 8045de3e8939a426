//! Unit conversion by a power of ten done on the decimal, not in binary:
//! `1.999 ms` is the double nearest to 0.001999 s, as a file in seconds
//! would give, where `1.999 * 1e-3` is `0.0019990000000000003` (two
//! roundings). The value differs from the product by an ulp at most, so
//! nothing meaningful changes; what is written back (a `simulate` output's
//! `time [s]`) is the number the user wrote, in SI.

/// The exponent `k` of a factor that is exactly the double `1e{k}` for
/// `k` in -12..=12 (the unit prefixes and percent); `None` for any other.
fn power_of_ten(factor: f64) -> Option<i32> {
    const P: [f64; 25] = [
        1e-12, 1e-11, 1e-10, 1e-9, 1e-8, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 1e-1, 1e0, 1e1, 1e2,
        1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12,
    ];
    P.iter().position(|&p| p == factor).map(|i| i as i32 - 12)
}

/// `x · 10^k` as the double nearest to the shortest decimal of `x` with
/// its exponent moved by `k` (a non-finite product, or zero, as is).
fn shift(x: f64, k: i32, buf: &mut zmij::Buffer) -> f64 {
    let product = x * 10f64.powi(k);
    if x == 0.0 || !product.is_finite() || product == 0.0 {
        return product;
    }
    let text = buf.format(x);
    let (mantissa, exp) = match text.split_once('e') {
        Some((m, e)) => (m, e.parse::<i32>().unwrap_or(0)),
        None => (text, 0),
    };
    // `<mantissa>e<exp + k>` on the stack: no allocation per value
    let mut out = [0u8; 48];
    let m = mantissa.as_bytes();
    if m.len() + 6 > out.len() {
        return product;
    }
    out[..m.len()].copy_from_slice(m);
    let mut n = m.len();
    out[n] = b'e';
    n += 1;
    let e = exp + k;
    if e < 0 {
        out[n] = b'-';
        n += 1;
    }
    // |e| < 400: three digits at most
    let a = e.unsigned_abs();
    for (d, show) in [
        (a / 100, a >= 100),
        ((a / 10) % 10, a >= 10),
        (a % 10, true),
    ] {
        if show {
            out[n] = b'0' + d as u8;
            n += 1;
        }
    }
    std::str::from_utf8(&out[..n])
        .ok()
        .and_then(|t| t.parse().ok())
        .unwrap_or(product)
}

/// Multiplies every value of `xs` by the unit factor `factor`: a power of
/// ten (`1e-3` for `[ms]`, `1e-2` for `[%]`) moves the decimal point of
/// each value's shortest decimal (see the module doc); any other factor
/// multiplies.
pub fn scale_decimal(xs: &mut [f64], factor: f64) {
    match power_of_ten(factor) {
        Some(0) => {}
        Some(k) => {
            let mut buf = zmij::Buffer::new();
            xs.iter_mut().for_each(|x| *x = shift(*x, k, &mut buf));
        }
        None => xs.iter_mut().for_each(|x| *x *= factor),
    }
}

/// One value `x` times `factor`, as [`scale_decimal`] scales it.
pub fn scaled_decimal(x: f64, factor: f64) -> f64 {
    let mut one = [x];
    scale_decimal(&mut one, factor);
    one[0]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn milliseconds_become_the_seconds_written() {
        // every time of a 1 kHz record written in [ms] with 3 decimals
        let mut bad_product = 0;
        for k in 0..20_000 {
            let text = format!("{:.3}", k as f64 * 0.001);
            let ms: f64 = text.parse().unwrap();
            let want: f64 = format!("{text}e-3").parse().unwrap();
            assert_eq!(scaled_decimal(ms, 1e-3), want, "{text} ms");
            bad_product += usize::from(ms * 1e-3 != want);
        }
        // the product misses often: the case the conversion is for
        assert!(bad_product > 1000, "{bad_product}");
        assert_eq!(scaled_decimal(1.999, 1e-3).to_string(), "0.001999");
        assert_eq!(scaled_decimal(7.0, 1e-2).to_string(), "0.07");
        assert_eq!(scaled_decimal(-2.5e-7, 1e-3), -2.5e-10);
    }

    #[test]
    fn other_factors_and_edges_multiply() {
        assert_eq!(scaled_decimal(3.0, 0.3048), 3.0 * 0.3048);
        assert_eq!(scaled_decimal(1e308, 1e3), f64::INFINITY);
        assert_eq!(scaled_decimal(0.0, 1e-3), 0.0);
        assert!(scaled_decimal(f64::NAN, 1e-3).is_nan());
        // within an ulp of the product, never further
        for x in [1.0 / 3.0, 6.02e23, 123.456, 5e-320] {
            let (a, b) = (scaled_decimal(x, 1e-3), x * 1e-3);
            assert!((a - b).abs() <= b.abs() * 2.3e-16 || a == b, "{x}: {a} {b}");
        }
    }
}
