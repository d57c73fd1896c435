//! Curves read from the reference files a case names and the tip histories compared with them:
//! a time history of the tip (`t, tip_x, tip_y, tip_z`), and two-column `x,y` curves (a static
//! reference's airspeed and coast angle).

use std::path::Path;

use aeroelastic::run::Row;

use crate::Error;

/// A reference time history: times and tip positions.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    /// Times, s (increasing).
    pub t: Vec<f64>,
    /// Tip positions, m.
    pub tip: Vec<[f64; 3]>,
}

/// Read a CSV with a header naming at least `t, tip_x, tip_y, tip_z`; `#` lines are comments.
pub fn read_curve(path: &Path) -> Result<Curve, Error> {
    let file = path.display().to_string();
    let text =
        std::fs::read_to_string(path).map_err(|e| Error::Reference { file: file.clone(), msg: e.to_string() })?;
    parse_curve(&text).map_err(|msg| Error::Reference { file, msg })
}

/// Parse CSV text (see [`read_curve`]).
pub fn parse_curve(text: &str) -> Result<Curve, String> {
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim_start().starts_with('#') && !l.trim().is_empty());
    let (_, header) = lines.next().ok_or("no header line")?;
    let cols: Vec<&str> = header.split(',').map(str::trim).collect();
    let col = |name: &str| cols.iter().position(|c| *c == name).ok_or(format!("no column `{name}`"));
    let (it, ix, iy, iz) = (col("t")?, col("tip_x")?, col("tip_y")?, col("tip_z")?);
    let mut c = Curve { t: Vec::new(), tip: Vec::new() };
    for (n, line) in lines {
        let f: Vec<&str> = line.split(',').collect();
        let get = |i: usize| -> Result<f64, String> {
            f.get(i)
                .ok_or(format!("line {}: too few columns", n + 1))?
                .trim()
                .parse::<f64>()
                .map_err(|e| format!("line {}: {e}", n + 1))
        };
        let t = get(it)?;
        if let Some(&last) = c.t.last()
            && t <= last
        {
            return Err(format!("line {}: time {t} does not increase", n + 1));
        }
        c.t.push(t);
        c.tip.push([get(ix)?, get(iy)?, get(iz)?]);
    }
    if c.t.is_empty() {
        return Err("no data rows".into());
    }
    Ok(c)
}

impl Curve {
    /// Linear interpolation of the tip at time `t`; `None` outside the curve's time range.
    pub fn tip_at(&self, t: f64) -> Option<[f64; 3]> {
        let n = self.t.len();
        if n == 0 || t < self.t[0] - 1e-12 || t > self.t[n - 1] + 1e-12 {
            return None;
        }
        let k = self.t.partition_point(|&x| x < t);
        if k == 0 {
            return Some(self.tip[0]);
        }
        if k >= n {
            return Some(self.tip[n - 1]);
        }
        let (t0, t1) = (self.t[k - 1], self.t[k]);
        let w = (t - t0) / (t1 - t0);
        let (a, b) = (self.tip[k - 1], self.tip[k]);
        Some([a[0] + w * (b[0] - a[0]), a[1] + w * (b[1] - a[1]), a[2] + w * (b[2] - a[2])])
    }
}

/// Time history of the tip of a run.
pub fn tip_curve(rows: &[Row]) -> Curve {
    let mut c = Curve { t: Vec::with_capacity(rows.len()), tip: Vec::with_capacity(rows.len()) };
    for r in rows {
        if c.t.last().is_none_or(|&l| r.t > l) {
            c.t.push(r.t);
            c.tip.push(r.tip);
        }
    }
    c
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// The distance d(t) = |a(t) − b(t + shift)| sampled at the times of `a` where `b` is defined.
pub fn tip_difference(a: &Curve, b: &Curve, shift: f64) -> Vec<(f64, f64)> {
    a.t.iter().zip(&a.tip).filter_map(|(&t, &p)| b.tip_at(t + shift).map(|q| (t, dist(p, q)))).collect()
}

/// Read a two-column CSV (a header line, then `x,y` rows; `#` comments allowed).
pub fn read_xy(path: &Path) -> Result<Vec<(f64, f64)>, Error> {
    let file = path.display().to_string();
    let text =
        std::fs::read_to_string(path).map_err(|e| Error::Reference { file: file.clone(), msg: e.to_string() })?;
    parse_xy(&text).map_err(|msg| Error::Reference { file, msg })
}

/// Parse the text of [`read_xy`].
pub fn parse_xy(text: &str) -> Result<Vec<(f64, f64)>, String> {
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim_start().starts_with('#') && !l.trim().is_empty());
    lines.next().ok_or("no header line")?;
    let mut out = Vec::new();
    for (n, line) in lines {
        let f: Vec<&str> = line.split(',').map(str::trim).collect();
        if f.len() < 2 {
            return Err(format!("line {}: two columns expected", n + 1));
        }
        let num = |s: &str| s.parse::<f64>().map_err(|e| format!("line {}: {e}", n + 1));
        let (x, y) = (num(f[0])?, num(f[1])?);
        if !(x.is_finite() && y.is_finite()) {
            return Err(format!("line {}: not finite", n + 1));
        }
        out.push((x, y));
    }
    if out.is_empty() {
        return Err("no data rows".into());
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_interpolates() {
        let c = parse_curve("# meta\nt,tip_x,tip_y,tip_z,extra\n0,1,0,0,9\n1,3,2,-2,9\n").unwrap();
        assert_eq!(c.tip_at(0.5), Some([2.0, 1.0, -1.0]));
        assert_eq!(c.tip_at(1.5), None);
    }

    #[test]
    fn rejects_missing_column_and_bad_number() {
        assert!(parse_curve("t,tip_x,tip_y\n0,1,2\n").unwrap_err().contains("tip_z"));
        assert!(parse_curve("t,tip_x,tip_y,tip_z\n0,1,x,2\n").unwrap_err().contains("line 2"));
    }
}
