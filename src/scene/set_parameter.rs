//! Editing a parsed scene document: one number at a field path (the `--parameter` of a
//! parameter sweep, a study's variant).

use serde_json::Value;

/// Sets the number at `path` (e.g. `elements[0].alpha`, `loads[1].cos`, `damping[0][0]`,
/// `fundamental.rpm`) in a parsed scene document; errors name what is missing.
pub fn set_parameter(doc: &mut Value, path: &str, x: f64) -> Result<(), String> {
    let mut cur = doc;
    let mut tokens = Vec::new();
    for part in path.split('.') {
        let (key, rest) = part.split_at(part.find('[').unwrap_or(part.len()));
        if !key.is_empty() {
            tokens.push(Err(key.to_string()));
        }
        for idx in rest.split('[').skip(1) {
            let i: usize = idx
                .trim_end_matches(']')
                .parse()
                .map_err(|_| format!("`{path}`: `[{idx}` is not an index"))?;
            tokens.push(Ok(i));
        }
    }
    for t in &tokens {
        cur = match t {
            Err(k) => cur
                .get_mut(k.as_str())
                .ok_or_else(|| format!("`{path}`: no field `{k}`"))?,
            Ok(i) => cur
                .get_mut(*i)
                .ok_or_else(|| format!("`{path}`: no entry [{i}]"))?,
        };
    }
    if !cur.is_number() {
        return Err(format!("`{path}` is not a number in the scene"));
    }
    // A whole value stays a whole number where the scene has one, so that whole-number fields
    // (`harmonics.count`, `teeth`, a load's `order`) take it.
    let whole = !cur.is_f64() && x.fract() == 0.0;
    *cur = if whole && (0.0..=u64::MAX as f64).contains(&x) {
        serde_json::json!(x as u64)
    } else if whole && (i64::MIN as f64..0.0).contains(&x) {
        serde_json::json!(x as i64)
    } else {
        serde_json::json!(x)
    };
    Ok(())
}
