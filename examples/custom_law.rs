//! A force law written by a user, outside hbal: a Hertzian (3/2-power) one-sided contact.
//!
//! `f(u) = k_h max(u - b, 0)^{3/2}`: a preloaded rolling-element or tooth contact that can lift
//! off. The example implements [`ForceLaw`], checks its derivatives, gives it a scene-file name,
//! solves the periodic response by harmonic balance and checks it against the time domain.
//!
//! Run: `cargo run --release --example custom_law`. With arguments the program is the whole
//! `hbal` command line with this law among the scene types ([`hbal::cli::main`]: solve, sweep,
//! report, plots), e.g. on the scene `examples/custom_law_hertz.toml`:
//!
//! ```text
//! cargo run --release --example custom_law -- report examples/custom_law_hertz.toml --from 0.3 --to 1.2 --out out/hertz
//! ```
//!
//! The same file compiles as the `main.rs` of a crate of your own with only these dependencies
//! (CI builds it that way and runs its `report`):
//!
//! ```toml
//! [dependencies]
//! hbal = { path = "path/to/hbal" }   # or the version you use
//! serde = { version = "1", features = ["derive"] }
//! typetag = "0.2"
//! ```

use hbal::compare::relative_error;
use hbal::force::{check_derivatives, ForceLaw, LinearPart};
use hbal::nalgebra::DMatrix;
use hbal::scene::Scene;
use hbal::timesim::TimeSimulation;
use hbal::{FixedPoint, HarmonicBalance, HarmonicBasis, Model};

/// One-sided Hertzian contact `f = k_h max(u - b, 0)^{3/2}`.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
struct HertzContact {
    /// Hertz constant k_h.
    k_h: f64,
    /// Clearance b.
    b: f64,
    /// Operating deflection where the iteration linearises (the static preload deflection).
    u_op: f64,
}

#[typetag::serde(name = "hertz_contact")]
impl ForceLaw for HertzContact {
    fn force(&self, _theta: f64, u: f64, _du: f64) -> f64 {
        let gap = (u - self.b).max(0.0);
        self.k_h * gap * gap.sqrt()
    }
    fn derivatives(&self, _theta: f64, u: f64, _du: f64) -> (f64, f64) {
        (1.5 * self.k_h * (u - self.b).max(0.0).sqrt(), 0.0)
    }
    /// Linearise at the operating point, not at u = 0 where the contact is open.
    fn linear_part(&self) -> LinearPart {
        LinearPart {
            stiffness: self.derivatives(0.0, self.u_op, 0.0).0,
            offset: self.force(0.0, self.u_op, 0.0)
                - self.derivatives(0.0, self.u_op, 0.0).0 * self.u_op,
            damping: 0.0,
        }
    }
    fn validate(&self, context: &str) -> hbal::Result<()> {
        for (name, v) in [("k_h", self.k_h), ("b", self.b)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(hbal::Error::invalid(context, name, v, "finite and >= 0"));
            }
        }
        Ok(())
    }
}

fn main() -> Result<std::process::ExitCode, Box<dyn std::error::Error>> {
    // With arguments: the `hbal` command line, which reads `type = "hertz_contact"` in scenes.
    if std::env::args_os().len() > 1 {
        return Ok(hbal::cli::main());
    }
    // Preload F0 = 1 on k_h = 1: static deflection (F0/k_h)^(2/3) = 1 beyond the clearance.
    let (k_h, b, f0, f1, c) = (1.0, 0.1, 1.0, 0.3, 0.1);
    let law = HertzContact {
        k_h,
        b,
        u_op: b + (f0 / k_h).powf(2.0 / 3.0),
    };

    let check = check_derivatives(&law, &[(0.0, 0.5, 0.0), (1.0, 1.3, 0.2), (2.0, 2.0, -1.0)]);
    println!(
        "derivative check: max relative error {:.1e}",
        check.max_relative_error
    );

    // The law has a scene-file name like the built-ins: a scene names it by `type`.
    let scene = Scene::from_str(
        &format!(
            r#"
dofs = ["x"]
mass = [[1.0]]
damping = [[{c}]]
fundamental = {{ rad_s = 0.6 }}
harmonics = {{ count = 16 }}
loads = [{{ dof = "x", order = 0, cos = {f0} }}, {{ dof = "x", order = 1, cos = {f1} }}]

[[elements]]
name = "hertz"
type = "hertz_contact"
connects = {{ x = 1.0 }}
k_h = {k_h}
b = {b}
u_op = {u_op}
"#,
            u_op = law.u_op
        ),
        "hertz.toml",
    )?;
    println!("scene element: {:?}", scene.model.elements()[0].law());
    // The same model in Rust.
    let model = Model::builder(&["x"])
        .mass_diagonal(&[1.0])
        .damping(DMatrix::from_element(1, 1, c))
        .element("hertz", &[("x", 1.0)], law)
        .load("x", 0, f0, 0.0)
        .load("x", 1, f1, 0.0)
        .build()?;
    assert_eq!(
        format!("{:?}", model.elements()[0].law()),
        format!("{:?}", scene.model.elements()[0].law())
    );

    let omega = 0.6;
    let hb = HarmonicBalance::new(&model, HarmonicBasis::new(omega, 16)?)?;
    let sol = FixedPoint::new()
        .with_gamma(0.3)?
        .with_tolerance(1e-12)?
        .with_max_iterations(2000)
        .solve(&hb, &mut hb.workspace())?;
    println!(
        "HB (H = 16): {} after {} iterations, residual {:.1e}, {:?}, max |x| = {:.6}, truncation estimate {:.1e}",
        sol.termination,
        sol.stats.iterations,
        sol.residual(),
        sol.wall_time,
        sol.max_abs(0),
        sol.truncation_estimate()
    );
    let td = TimeSimulation {
        rtol: 1e-11,
        steady_tolerance: 1e-10,
        samples: 256,
        // From the static preload deflection, independent of the HB result.
        initial: Some((vec![b + (f0 / k_h).powf(2.0 / 3.0)], vec![0.0])),
        ..TimeSimulation::default()
    }
    .run(&model, omega)?;
    let err = relative_error(sol.harmonics(), &td.harmonics, 1, 16);
    println!(
        "time domain: {} periods, {} steps, {:?}; HB relative error against it: {err:.2e}",
        td.periods, td.steps, td.wall_time
    );
    if !sol.is_converged() || err > 1e-6 {
        return Err(format!("HB and the time domain disagree: {err:.2e}").into());
    }
    Ok(std::process::ExitCode::SUCCESS)
}
