//! `hbal solve`: solve one scene with its (or the given) solver, from the linear solution or a
//! `--start` file, compute the orbit's Floquet stability, print a summary or one JSON object, and
//! optionally write harmonics.csv, time_series.csv and SVG plots.

use super::solve_files::{write_outputs, OutputLabel};
use super::{element_report, load, multipliers_json, start, Failure, SolverArgs};
use super::{solve_exact, solve_hints};
use anyhow::Context;
use hbal::stability::Floquet;
use hbal::HarmonicBalance;
use serde_json::json;
use std::path::Path;
use std::time::Instant;

/// Options of `hbal solve` besides the solver overrides.
pub(crate) struct SolveOptions<'a> {
    pub(crate) start: Option<&'a Path>,
    pub(crate) stability: bool,
    /// Fall back to the other solvers and homotopies where the scene's method fails.
    pub(crate) fallback: bool,
    pub(crate) json: bool,
    pub(crate) out: Option<&'a Path>,
    /// Keep the JSON document here instead of printing anything (for `hbal report`).
    pub(crate) capture: super::Capture<'a>,
}

pub(crate) fn solve(path: &Path, args: &SolverArgs, opts: SolveOptions) -> Result<u8, Failure> {
    let as_json = opts.json || opts.capture.is_some();
    let out = opts.out;
    let scene = load(path, args)?;
    if let Some(dir) = out {
        super::prepare_out(dir)?;
    }
    let start = opts.start.map(|p| start::read(p, &scene)).transpose()?;
    if let (Some(file), Some(s)) = (opts.start, &start) {
        if let Some(w) = s.omega {
            let here = scene.basis.omega();
            if (w - here).abs() > 1e-9 * here {
                eprintln!(
                    "note: --start {} was computed at {w} rad/s; the scene is at {here} rad/s",
                    file.display()
                );
            }
        }
        if s.dropped_orders > 0 {
            eprintln!(
                "note: --start {}: {} harmonic order(s) above H = {} dropped",
                file.display(),
                s.dropped_orders,
                scene.basis.harmonics()
            );
        }
    }
    if let Some(dir) = out {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("--out: cannot create {}", dir.display()))?;
    }
    let started = Instant::now();
    let solve_seconds;
    // The path that found the orbit where the scene's method alone did not.
    let mut found_by: Option<String> = None;
    let mut exact = None;
    // Automatic harmonics handed over to the exact piecewise solution at the cap.
    let mut switched = false;
    let (sol, estimate, auto) = match scene.auto {
        Some(auto) => {
            if start.is_some() {
                return Err(anyhow::anyhow!(
                    "{}: --start needs a fixed H: give --harmonics N (automatic harmonics start from the linear solution)",
                    scene.file
                )
                .into());
            }
            let a = hbal::solve::solve_auto(&scene.model, scene.basis, &scene.method, auto)
                .map_err(|e| super::failure(e, &scene.file))?;
            solve_seconds = started.elapsed().as_secs_f64();
            found_by = a.found_by;
            exact = a.exact;
            switched = a.switched_to_exact;
            (
                a.solution,
                Some(Ok(a.estimate)),
                Some((auto, a.levels, a.capped)),
            )
        }
        None if matches!(scene.method, hbal::solve::Method::PiecewiseExact(_)) => {
            if let Some(file) = opts.start {
                eprintln!(
                    "note: --start {} is not used: the exact piecewise solution needs no start",
                    file.display()
                );
            }
            let e = hbal::solve::PiecewiseExact::new()
                .solve_exact(&scene.model, &scene.basis)
                .map_err(|e| super::failure(e, &scene.file))?;
            solve_seconds = started.elapsed().as_secs_f64();
            let out = (e.solution.clone(), Some(Ok(e.estimate)), None);
            exact = Some(e);
            out
        }
        None => {
            let hb = HarmonicBalance::with_formulation(&scene.model, scene.basis, args.formulation)
                .with_context(|| scene.file.clone())?;
            // The scene's method, and where it fails the others, the load homotopy and
            // continuation in the speed (named in the output).
            let continuation = hbal::continuation::Continuation {
                method: scene.method,
                formulation: args.formulation,
                ..Default::default()
            };
            let initial = start.as_ref().map(|s| s.harmonics.as_slice());
            let (sol, how) = if opts.fallback {
                hbal::continuation::solve_with_fallbacks(
                    &scene.model,
                    scene.basis,
                    &continuation,
                    initial,
                )
            } else {
                let mut ws = hb.workspace();
                scene.method.solve(&hb, initial, &mut ws).map(|s| (s, None))
            }
            .map_err(|e| super::failure(e, &scene.file))?;
            found_by = how;
            solve_seconds = started.elapsed().as_secs_f64();
            // The error of the harmonics, against the solution with 2H (module
            // hbal::solve::accuracy); none for an unconverged iterate.
            let estimate = sol.is_converged().then(|| {
                hbal::solve::estimate_error(&scene.model, &sol).map_err(|e| e.to_string())
            });
            solve_hints::print(&scene, Some(&hb), estimate.as_ref());
            (sol, estimate, None)
        }
    };
    if scene.auto.is_some() || exact.is_some() {
        solve_hints::print(&scene, None, estimate.as_ref());
    }
    let extremes = exact.as_ref().map(|e| e.extremes());
    // Stability of a converged orbit (an unconverged iterate is no orbit to judge).
    let started = Instant::now();
    // Laws with memory in a large model: no multipliers rather than wrong ones (not a failure
    // of the solve); a small one is shot on the time-domain model.
    let unavailable = scene
        .model
        .memory_element()
        .filter(|_| !hbal::stability::memory_stability_available(&scene.model))
        .map(|e| {
            format!(
                "stability not available for laws with memory (element `{}`) in a free-free model or above {} DOFs",
                e.name(),
                hbal::stability::MAX_MEMORY_DOFS
            )
        });
    let stability: Option<Result<Floquet, String>> =
        (opts.stability && sol.is_converged() && unavailable.is_none()).then(|| {
            let floquet = match &exact {
                Some(e) => Ok(e.floquet()),
                None => sol.stability(&scene.model),
            };
            floquet
                .map_err(|e| e.to_string())
                .and_then(|f| super::check_finite(&f).map(|_| f))
        });
    let stability_seconds = started.elapsed().as_secs_f64();
    // Extremes of the exact method from its closed form, else from the harmonics.
    let max_abs = match &extremes {
        Some(x) => x.max_abs(),
        None => sol.max_abs_all(),
    };
    let elements = hbal::report::element_outputs(&scene.model, &sol)
        .map(|outputs| solve_exact::element_outputs(outputs, extremes.as_ref()))
        .map_err(|e| e.to_string());
    let subharmonic = sol.basis().subharmonic();
    let order = |k| element_report::order_of(k, scene.fundamental_order, subharmonic);
    let dofs: Vec<_> = sol
        .dof_names()
        .iter()
        .enumerate()
        .map(|(i, name)| {
            json!({
                "name": name,
                "max_abs": max_abs[i],
                "harmonics": (0..=sol.basis().harmonics()).map(|k| {
                    let (c, s) = sol.cos_sin(i, k);
                    // `order` is the harmonic index, kept for `--start` files.
                    json!({"order": k, "harmonic": k, "shaft_order": order(k), "cos": c, "sin": s})
                }).collect::<Vec<_>>(),
            })
        })
        .collect();
    if as_json {
        let stability_json = match (&stability, &unavailable) {
            (None, Some(u)) if opts.stability => json!({ "unavailable": u }),
            (None, _) => serde_json::Value::Null,
            (Some(Ok(f)), _) => json!({
                "stable": f.is_stable(),
                "orbit": f.orbit,
                "orbit_distance": f.orbit_distance,
                "other_orbit": f.other_orbit,
                "max_abs": f.max_abs(),
                "multipliers": multipliers_json(f),
                "moduli": f.multipliers.iter().map(|m| m.norm()).collect::<Vec<_>>(),
                "neutral": f.neutral,
                "orbit_correction": f.orbit_correction,
                "polished": f.polished,
                "seconds": stability_seconds,
                "reduction": f.reduction,
            }),
            (Some(Err(e)), _) => json!({ "error": e }),
        };
        let doc = json!({
            "converged": sol.is_converged(),
            "termination": sol.termination.to_string(),
            "method": if switched { "piecewise_exact" } else { scene.method.name() },
            "switched_to_exact": switched,
            "found_by": found_by,
            "iterations": sol.stats.iterations,
            "residual": sol.residual(),
            "truncation_estimate": sol.truncation_estimate(),
            "error_estimate": match &estimate {
                None => serde_json::Value::Null,
                Some(Ok(e)) => {
                    let mut v = json!({"relative": e.relative, "kept_harmonics": e.kept_harmonics, "reference_harmonics": e.reference_harmonics, "lower_bound": e.lower_bound});
                    if let (Some(o), serde_json::Value::Object(q)) = (v.as_object_mut(), super::quantity_report::estimate_fields(&scene.model, e)) {
                        o.extend(q);
                    }
                    v
                }
                Some(Err(e)) => json!({"error": e}),
            },
            "auto_harmonics": auto.as_ref().map(|(a, levels, capped)| json!({
                "tolerance": a.tolerance,
                "max": a.max_harmonics,
                "control": a.control,
                "reached": !capped,
                "levels": levels,
            })),
            // Where max_abs and the elements' extremes come from.
            "extremes_from": match &extremes {
                Some(x) => json!({"closed_form": {"intervals": x.intervals, "resolved": x.resolved}}),
                None => json!("harmonics"),
            },
            "fundamental_rad_s": sol.basis().omega(),
            "harmonics": sol.basis().harmonics(),
            "samples": sol.basis().samples(),
            "solve_seconds": solve_seconds,
            "start": opts.start.filter(|_| exact.is_none()).map(|p| p.display().to_string()),
            "stability": stability_json,
            "dofs": dofs,
            "elements": match &elements {
                Ok(e) => element_report::json(e, order),
                Err(e) => json!({ "error": e }),
            },
            "history": sol.history,
        });
        super::emit(doc, opts.capture);
    } else {
        say!(
            "{}: {} ({}) after {} iteration{}{}, relative residual {:.2e}, solve {:.3} ms",
            scene.file,
            sol.termination,
            if switched {
                "piecewise_exact"
            } else if found_by.is_some() && sol.is_converged() {
                "by a fallback, below"
            } else {
                scene.method.name()
            },
            sol.stats.iterations,
            if sol.stats.iterations == 1 { "" } else { "s" },
            if start.is_some() && exact.is_none() && found_by.is_none() {
                " from --start"
            } else {
                ""
            },
            sol.residual(),
            solve_seconds * 1e3
        );
        if let Some(how) = &found_by {
            say!("  {how}");
        }
        say!(
            "  fundamental {:.6} rad/s, H = {}, N = {}, {}",
            sol.basis().omega(),
            sol.basis().harmonics(),
            sol.basis().samples(),
            match &estimate {
                Some(Ok(e)) => format!(
                    "error estimate {}{:.1e}, of harmonics 0..{} {:.1e} (against H = {}){}",
                    if e.lower_bound { "at least " } else { "" },
                    e.relative,
                    sol.basis().harmonics(),
                    e.kept_harmonics,
                    e.reference_harmonics,
                    super::quantity_report::summary(&scene.model, e)
                ),
                Some(Err(e)) => format!("no error estimate: {e}"),
                None => "no error estimate (not converged)".to_string(),
            }
        );
        if let Some((a, levels, capped)) = &auto {
            let steps: Vec<String> = levels
                .iter()
                .map(|l| format!("H = {} → {:.1e}", l.harmonics, l.estimate))
                .collect();
            say!(
                "  harmonics: auto, tolerance {:.0e} on {}{}: {}",
                a.tolerance,
                a.control.what(),
                if *capped { " (NOT reached)" } else { "" },
                steps.join(", ")
            );
            if switched {
                say!(
                    "  harmonic balance stopped at the cap H = {} above the tolerance; the scene is linear with piecewise-constant coefficients, so the exact piecewise solution answers instead (the levels after the cap are its own): its harmonics 0..H are exact, its time series and extremes come from its closed form in time",
                    a.max_harmonics
                );
            }
        }
        if let Some(x) = &extremes {
            say!(
                "  extremes from the closed form in time ({} intervals{}), not from the harmonics 0..{}",
                x.intervals,
                if x.resolved {
                    ""
                } else {
                    "; APPROXIMATE between them: the work budget allows fewer than 32 per period of the fastest motion"
                },
                sol.basis().harmonics()
            );
        }
        for (i, name) in sol.dof_names().iter().enumerate() {
            say!("  max |q| {name}: {:.6e}", max_abs[i]);
        }
        match &elements {
            Ok(e) => element_report::lines(e).iter().for_each(|l| say!("  {l}")),
            Err(e) => say!("  element outputs: {e}"),
        }
        match &stability {
            None if opts.stability && unavailable.is_some() => {
                say!("  {}", unavailable.as_deref().unwrap_or_default())
            }
            None if opts.stability => {
                say!("  stability: not computed (the solve did not converge)")
            }
            None => {}
            Some(Ok(f)) if exact.is_some() => say!(
                "  stability: {}, max |μ| = {} ({} multiplier{} of the exact monodromy matrix{}), {:.1} ms",
                if f.is_stable() { "stable" } else { "unstable" },
                super::modulus(f.max_abs()),
                f.multipliers.len(),
                if f.multipliers.len() == 1 { "" } else { "s" },
                if f.neutral > 0 {
                    format!(", {} neutral of the rigid body", f.neutral)
                } else {
                    String::new()
                },
                stability_seconds * 1e3
            ),
            Some(Ok(f)) if f.other_orbit.is_some() => say!(
                "  stability: {}, max |μ| = {} ({} multiplier{}, {} neutral), {:.1} ms; shooting from the HB orbit found another periodic orbit {:.1e} of the dynamic range away (a strongly unstable orbit single shooting cannot hold): the multipliers are the HB orbit's own",
                if f.is_stable() { "stable" } else { "unstable" },
                super::modulus(f.max_abs()),
                f.multipliers.len(),
                if f.multipliers.len() == 1 { "" } else { "s" },
                f.neutral,
                stability_seconds * 1e3,
                f.other_orbit.unwrap_or_default(),
            ),
            Some(Ok(f)) => say!(
                "  stability: {}, max |μ| = {} ({} multiplier{}, {} neutral), orbit correction {:.1e}{}, {:.1} ms",
                if f.is_stable() { "stable" } else { "unstable" },
                super::modulus(f.max_abs()),
                f.multipliers.len(),
                if f.multipliers.len() == 1 { "" } else { "s" },
                f.neutral,
                f.orbit_correction,
                match (f.polished, f.orbit_distance > hbal::stability::OTHER_ORBIT_DISTANCE) {
                    (false, _) if f.reduction.as_ref().is_some_and(|r| r.krylov.is_some()) => {
                        " (multipliers along the HB orbit)".to_string()
                    }
                    (false, _) => " (shooting did not converge: multipliers along the HB orbit)".to_string(),
                    (true, true) => format!(
                        " (the exact orbit starts {:.1e} of the dynamic range from the HB orbit: the HB solution is that far off, or the shooting found a neighbouring orbit of the same kind)",
                        f.orbit_distance
                    ),
                    (true, false) => String::new(),
                },
                stability_seconds * 1e3
            ),
            Some(Err(e)) => say!("  stability: failed: {e}"),
        }
        if let Some(Ok(Floquet {
            reduction: Some(r), ..
        })) = &stability
        {
            if let Some(actions) = r.krylov {
                say!(
                    "  stability by the Arnoldi iteration on the monodromy action: {actions} actions on all {} DOFs (no 2n × 2n matrix), leading multipliers to about {:.1e} (Krylov and integration parts)",
                    r.dofs,
                    r.estimate.unwrap_or(f64::NAN)
                );
            }
            let estimate = match (r.estimate, r.comparison_dofs) {
                (Some(e), Some(wider)) => {
                    format!(", multipliers to about {e:.1e} (against {wider} coordinates)")
                }
                // Every mode kept: a similarity transform of the full model, nothing to compare.
                (Some(_), None) => {
                    ", every mode kept: the model's own multipliers (no reduction)".to_string()
                }
                (None, _) => String::new(),
            };
            if r.krylov.is_none() {
                say!(
                    "  stability on a reduced basis: {} coordinates ({} modes below {:.0} rad/s, {} attachment modes){estimate}",
                    r.dofs,
                    r.modes,
                    r.cutoff,
                    r.attachment
                );
            }
        }
    }
    match &stability {
        Some(Ok(f)) if !f.is_stable() => eprintln!(
            "warning: the converged orbit is unstable (max |μ| = {:.6}): a time simulation would leave it",
            f.max_abs()
        ),
        Some(Err(e)) => eprintln!("error: {}: stability computation failed: {e}", scene.file),
        _ => {}
    }
    if let Some(dir) = out {
        // Files of an unconverged iterate say so in their names and plot titles.
        let prefix = if sol.is_converged() {
            ""
        } else {
            "not_converged_"
        };
        let label = OutputLabel {
            title: format!(
                "{} at {} {}{}",
                scene.file,
                super::speed_text(sol.basis().omega() / scene.omega_per_speed),
                scene.speed_unit,
                if sol.is_converged() {
                    String::new()
                } else {
                    format!(" - NOT CONVERGED ({})", sol.termination)
                }
            ),
            prefix,
        };
        let series = exact.as_ref().and_then(solve_exact::time_series);
        let mut written = write_outputs(dir, &sol, &label, order, series)
            .with_context(|| format!("--out: cannot write {}", dir.display()))?;
        if let Ok(e) = &elements {
            element_report::write_csv(&dir.join(format!("{prefix}elements.csv")), e, order)
                .with_context(|| format!("--out: cannot write {}", dir.display()))?;
            written.insert(1, format!("{prefix}elements.csv"));
        }
        if !as_json {
            say!("  wrote {} to {}", written.join(", "), dir.display());
        }
    }
    let stability_failed = matches!(stability, Some(Err(_)));
    if !sol.is_converged() {
        eprintln!(
            "error: {}: the solve did not converge: {}",
            scene.file, sol.termination
        );
    }
    let capped = matches!(&auto, Some((_, _, true)));
    if let Some((a, levels, true)) = &auto {
        // The quantity that limits it, where the estimate has one.
        let limiting = match &estimate {
            Some(Ok(e)) => e
                .worst_quantity
                .map(|q| {
                    format!(
                        "; worst quantity {} {:.1e} of its range",
                        q.quantity.name(&scene.model),
                        q.error
                    )
                })
                .unwrap_or_default(),
            _ => String::new(),
        };
        eprintln!(
            "error: {}: automatic harmonics: the estimated error of {} {:.1e} is above the tolerance {:.0e} at the cap H = {} (harmonics.max){limiting}",
            scene.file,
            a.control.what(),
            levels.last().map_or(f64::NAN, |l| l.estimate),
            a.tolerance,
            levels.last().map_or(0, |l| l.harmonics),
        );
    }
    Ok(if sol.is_converged() && !stability_failed && !capped {
        0
    } else {
        1
    })
}
