//! `sweep.svg`: one column of `index.csv` against the varied keys.
//!
//! The x axis is the first varied key with numeric values: a number, or an
//! array in which exactly one component varies across the runs (e.g.
//! `initial.position = [0.0, h]` plots against `h`, labelled
//! `initial.position[1]`). Every combination of the other keys is one
//! line (for two keys: one line per value of the other key). Runs with an
//! empty cell in the column are left out.

use plotters::prelude::*;

use crate::plot::{Entry, LEGEND_WIDTH, PALETTE, Style, err, range, side_legend, tick};
use crate::sweep::Row;

/// Numbers of a formatted value: `0.4` → `[0.4]`, `[0.0, 0.5]` →
/// `[0.0, 0.5]`; `None` when anything is not a number.
fn numbers(v: &str) -> Option<Vec<f64>> {
    let inner = v
        .trim()
        .strip_prefix('[')
        .and_then(|s| s.strip_suffix(']'))
        .unwrap_or(v);
    inner
        .split(',')
        .map(|s| s.trim().parse::<f64>().ok().filter(|x| x.is_finite()))
        .collect()
}

/// The x values of key `k` and its axis label, when numeric.
fn numeric_view(key: &str, k: usize, rows: &[Row]) -> Option<(String, Vec<f64>)> {
    let nums: Vec<Vec<f64>> = rows
        .iter()
        .map(|r| numbers(r.values.get(k)?))
        .collect::<Option<_>>()?;
    let len = nums.first()?.len();
    if nums.iter().any(|n| n.len() != len) {
        return None;
    }
    let scalar = !rows[0].values[k].trim_start().starts_with('[');
    if scalar {
        return Some((key.to_owned(), nums.iter().map(|n| n[0]).collect()));
    }
    let varying: Vec<usize> = (0..len)
        .filter(|&c| nums.iter().any(|n| n[c] != nums[0][c]))
        .collect();
    match varying.as_slice() {
        [c] => Some((format!("{key}[{c}]"), nums.iter().map(|n| n[*c]).collect())),
        [] if len == 1 => Some((format!("{key}[0]"), nums.iter().map(|n| n[0]).collect())),
        _ => None,
    }
}

/// The unit of a configuration key, from its last component (`None` when
/// it has none or is unknown).
fn key_unit(key: &str) -> Option<&'static str> {
    let last = key.rsplit('.').next().unwrap_or(key);
    Some(match last {
        "omega_deg" | "rate_deg" => "°/s",
        l if l.ends_with("_deg") => "°",
        "dt" | "duration" => "s",
        "mu_static" | "mu_dynamic" | "upper_com" | "lower_com" => "dimensionless",
        "position" | "side" | "height" | "amplitude" | "wavelength" | "step_height" => "m",
        l if l.ends_with("_length") => "m",
        "velocity" => "m/s",
        "gravity" => "m/s²",
        l if l.ends_with("mass") => "kg",
        l if l.ends_with("inertia") => "kg·m²",
        "kp" => "N·m/rad",
        "kd" => "N·m·s/rad",
        "stride" => "steps",
        _ => return None,
    })
}

/// The SVG, or why there is none (no numeric key, no value to plot).
pub fn sweep_svg(keys: &[String], rows: &[Row], column: &str) -> Result<String, String> {
    if rows.is_empty() {
        return Err("no finished run".into());
    }
    let Some((xk, (x_label, xs))) = keys
        .iter()
        .enumerate()
        .find_map(|(k, key)| numeric_view(key, k, rows).map(|v| (k, v)))
    else {
        return Err("no varied key has numeric values".into());
    };
    // Group by the other keys, in order of first appearance.
    let mut groups: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for (r, &x) in rows.iter().zip(&xs) {
        let label: Vec<String> = keys
            .iter()
            .enumerate()
            .filter(|(k, _)| *k != xk)
            .map(|(k, key)| format!("{key} = {}", r.values.get(k).map_or("", String::as_str)))
            .collect();
        let label = label.join(", ");
        let Some(y) = r.column(column) else { continue };
        match groups.iter_mut().find(|g| g.0 == label) {
            Some(g) => g.1.push((x, y)),
            None => groups.push((label, vec![(x, y)])),
        }
    }
    if groups.is_empty() {
        return Err(format!("column {column} is empty in every run"));
    }
    for g in &mut groups {
        g.1.sort_by(|a, b| a.0.total_cmp(&b.0));
    }
    let (x0, x1) = range(groups.iter().flat_map(|g| g.1.iter().map(|p| &p.0)));
    let (y0, y1) = range(groups.iter().flat_map(|g| g.1.iter().map(|p| &p.1)));
    let y_desc = match column {
        "touchdown" => "first touchdown (s)".to_owned(),
        c if c.starts_with("touchdown") || c.starts_with("slip") || c == "wall_seconds" => {
            format!("{c} (s)")
        }
        c if c.starts_with("peak") => format!("{c} (N)"),
        "steps" => "steps solved".to_owned(),
        c => c.to_owned(),
    };
    let x_desc = match key_unit(&keys[xk]) {
        Some(u) => format!("{x_label} ({u})"),
        None => x_label.clone(),
    };
    let mut buf = String::new();
    {
        let labelled = groups.len() > 1 || !groups[0].0.is_empty();
        let legend_width = if labelled { 2 * LEGEND_WIDTH } else { 0 };
        let root = SVGBackend::with_string(&mut buf, (960 + legend_width, 540)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let (left, right) = root.split_horizontally(960);
        let mut chart = ChartBuilder::on(&left)
            .caption(format!("{y_desc} vs {x_label}"), ("sans-serif", 22))
            .margin(14)
            .x_label_area_size(48)
            .y_label_area_size(70)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc(x_desc.as_str())
            .y_desc(y_desc.as_str())
            .x_label_formatter(&tick)
            .y_label_formatter(&tick)
            .light_line_style(WHITE.mix(0.0))
            .draw()
            .map_err(err)?;
        let mut entries = Vec::new();
        for (i, (label, pts)) in groups.iter().enumerate() {
            let color = PALETTE[i % PALETTE.len()];
            chart
                .draw_series(LineSeries::new(pts.iter().copied(), color.stroke_width(2)))
                .map_err(err)?;
            entries.push(Entry {
                label: label.clone(),
                style: Style {
                    color,
                    width: 2,
                    dashed: false,
                },
            });
            chart
                .draw_series(pts.iter().map(|&p| Circle::new(p, 3, color.filled())))
                .map_err(err)?;
        }
        if labelled {
            side_legend(&right, &entries)?;
        }
        root.present().map_err(err)?;
    }
    Ok(buf)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_carry_their_units() {
        assert_eq!(key_unit("terrain.mu_static"), Some("dimensionless"));
        assert_eq!(key_unit("initial.position"), Some("m"));
        assert_eq!(key_unit("initial.leg3.theta_deg"), Some("°"));
        assert_eq!(key_unit("initial.omega_deg"), Some("°/s"));
        assert_eq!(key_unit("body.mass"), Some("kg"));
        assert_eq!(key_unit("time.dt"), Some("s"));
        assert_eq!(key_unit("output.name"), None);
    }
}
