//! Element outputs of `hbal solve` ([`hbal::report::element_outputs`]) as text lines and
//! `elements.csv` (their JSON form is the library's, `hbal::analysis`); every harmonic is
//! named by its index k (`harmonic`) and by the order it is of the scene's reference speed
//! (`shaft_order`; the DOFs' `order` is the index k).

use hbal::report::ElementOutput;
use std::path::Path;

pub(crate) use hbal::analysis::order_of;

/// One line per element for the text output.
pub(crate) fn lines(outputs: &[ElementOutput]) -> Vec<String> {
    outputs
        .iter()
        .map(|e| {
            let mut line = format!(
                "element {} ({}): u in [{:.6e}, {:.6e}], f in [{:.6e}, {:.6e}], mean f {:.6e}",
                e.name,
                e.kind,
                e.coordinate.min,
                e.coordinate.max,
                e.force.min,
                e.force.max,
                e.force.mean()
            );
            if let Some(m) = &e.mesh {
                line += &format!(
                    "; transmission error {:.4} {u} mean, {:.4} {u} peak to peak; mesh force {:.6e} mean, {:.6e} max, dynamic factor {:.4}",
                    m.te_mean,
                    m.te_peak_to_peak,
                    m.force_mean,
                    m.force_max,
                    m.dynamic_factor,
                    u = m.te_unit
                );
            }
            if !e.states.is_empty() {
                let states: Vec<String> = e
                    .states
                    .iter()
                    .map(|(n, f)| format!("{n} {:.1} %", 100.0 * f))
                    .collect();
                line += &format!("; {}", states.join(", "));
            }
            line
        })
        .collect()
}

/// `elements.csv`: `element,quantity,harmonic,shaft_order,cos,sin` for the coordinate `u` and the
/// force `f` of every element (quoted where a name needs it).
pub(crate) fn write_csv(
    path: &Path,
    outputs: &[ElementOutput],
    order: impl Fn(usize) -> f64,
) -> anyhow::Result<()> {
    let mut w = csv::Writer::from_path(path)?;
    w.write_record([
        "element",
        "quantity",
        "harmonic",
        "shaft_order",
        "cos",
        "sin",
    ])?;
    for e in outputs {
        for (quantity, s) in [("u", &e.coordinate), ("f", &e.force)] {
            for (k, x) in s.harmonics.iter().enumerate() {
                let (c, sn) = hbal::harmonic::cos_sin(*x);
                w.write_record([
                    e.name.clone(),
                    quantity.to_string(),
                    k.to_string(),
                    format!("{}", order(k)),
                    format!("{c:e}"),
                    format!("{sn:e}"),
                ])?;
            }
        }
    }
    w.flush()?;
    Ok(())
}
