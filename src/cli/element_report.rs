//! Element outputs of `hbal solve` ([`hbal::report::element_outputs`]) as text lines (their
//! JSON form is the library's, `hbal::analysis`; `elements.csv` is
//! [`hbal::render::element_csv`]).

use hbal::report::ElementOutput;

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
