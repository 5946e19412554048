//! What the summary says where a sweep reports some DOFs in full (`--dofs`, chosen by
//! [`hbal::analysis::reported_dofs`]).

use hbal::Model;

/// What the summary says when not every DOF is reported.
pub(crate) fn note(model: &Model, reported: &[usize]) -> Option<String> {
    let n = model.n_dofs();
    (reported.len() < n).then(|| {
        format!(
            "harmonics and response plots of {} of {n} DOFs (--dofs NAME,... or --dofs all for more; max |q| of all)",
            reported.len()
        )
    })
}
