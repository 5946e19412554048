//! `hbal modes`: runs the library's modes analysis ([`hbal::analysis::modes`]: natural
//! frequencies and mode shapes about the periodic solution, with the one- and two-tooth
//! bounds of time-varying meshes, the excitation orders and the critical speeds) and renders
//! it as a table or JSON; a Campbell diagram and `modes.csv` with `--out`.

use super::{load, Failure, SolverArgs};
use hbal::analysis::{ModesAnalysis, ModesSettings};
use hbal::report::NaturalFrequencies;
use std::path::Path;

/// Options of `hbal modes`.
pub(crate) struct ModesOptions<'a> {
    pub(crate) from: Option<f64>,
    pub(crate) to: Option<f64>,
    pub(crate) max_hz: Option<f64>,
    pub(crate) json: bool,
    pub(crate) out: Option<&'a Path>,
}

pub(crate) fn modes(path: &Path, args: &SolverArgs, opts: ModesOptions) -> Result<u8, Failure> {
    let as_json = opts.json;
    let scene = load(path, args)?;
    if let Some(dir) = opts.out {
        hbal::render::prepare_out(dir, &hbal::render::modes_files())
            .map_err(|e| super::failure(e, &scene.file))?;
    }
    let settings = ModesSettings {
        from: opts.from,
        to: opts.to,
        max_hz: opts.max_hz,
        formulation: args.formulation,
    };
    let a = hbal::analysis::modes(&scene, &settings).map_err(|e| super::failure(e, &scene.file))?;
    let Some(nf) = &a.natural else {
        if opts.json {
            // The document still comes, marked: what failed instead of the modes (the
            // report says it in its page instead).
            say!("{}", a.to_json());
        }
        return Err(Failure {
            code: 1,
            error: anyhow::anyhow!(
                "{}: the operating point did not converge ({}): no linearisation",
                a.file,
                a.termination
            ),
        });
    };
    if as_json {
        say!("{}", a.to_json());
    } else {
        table(&a, nf);
    }
    if let Some(dir) = opts.out {
        let mut warnings = Vec::new();
        let written = hbal::render::write_modes_files(dir, &scene, &a, &mut warnings)
            .map_err(|e| super::failure(e, &scene.file))?;
        super::print_warnings(&warnings);
        if !as_json {
            say!("  wrote {} to {}", written.join(", "), dir.display());
        }
    }
    Ok(0)
}

/// The table of modes, the excitation orders and the critical speeds.
fn table(a: &ModesAnalysis, nf: &NaturalFrequencies) {
    let limit = if a.max_hz.is_finite() {
        format!("{} Hz", a.max_hz)
    } else {
        "the highest".into()
    };
    let at = if a.linear {
        "a linear model (no operating point needed)".to_string()
    } else {
        format!(
            "linearised on the orbit at {} {}",
            a.operating_speed.unwrap_or(f64::NAN),
            a.unit
        )
    };
    say!(
        "{}: {} modes up to {limit} ({} rigid), {at}",
        a.file,
        nf.mean.len(),
        nf.rigid
    );
    say!("  mode   mean Hz    one-tooth Hz   two-tooth Hz   largest DOF");
    for (i, f) in nf.mean.iter().enumerate() {
        let top = nf.shapes.column(i).iamax();
        say!(
            "  {:>4}  {:>11.4}  {:>11.4}    {:>11.4}     {}",
            i + 1,
            f,
            nf.lower.get(i).copied().unwrap_or(f64::NAN),
            nf.upper.get(i).copied().unwrap_or(f64::NAN),
            a.dofs[top]
        );
    }
    let list: Vec<String> = a.orders.iter().map(|o| format!("{o}")).collect();
    say!("  excitation orders: {}", list.join(", "));
    for c in &a.critical {
        say!(
            "  critical speed {:.2} {}: order {} meets mode {}",
            c.speed,
            a.unit,
            c.order,
            c.mode
        );
    }
}
