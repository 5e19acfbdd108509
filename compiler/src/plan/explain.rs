//! What explanations of both dimensions share: numbers for people, the
//! plan's header and the line of one step.

/// A number for people: at most 4 decimals, trailing zeros dropped.
pub fn num(x: f64) -> String {
    crate::format::rounded(x, 4)
}

/// The first line of `dofplan plan`, planar or spatial: the mechanism, its
/// file, the counts of steps and branches, and the inputs with their kinds.
pub(crate) fn header<'a>(
    mechanism: &str,
    source: &str,
    steps: usize,
    branches: usize,
    inputs: impl Iterator<Item = (&'a str, crate::model::InputKind)>,
) -> String {
    let inputs: Vec<String> = inputs.map(|(n, k)| format!("{n} ({})", k.name())).collect();
    format!(
        "plan for {mechanism} ({source}): {steps} steps, {branches} branch{}, inputs: {}\n",
        if branches == 1 { "" } else { "es" },
        if inputs.is_empty() {
            "none".to_string()
        } else {
            inputs.join(", ")
        }
    )
}

/// One line of `dofplan plan`, planar or spatial: the step's number (from
/// 0), its explanation and what it serves.
pub(crate) fn step_line(i: usize, text: &str, serves: &[String]) -> String {
    if serves.is_empty() {
        format!("{i:>4}  {text}\n")
    } else {
        format!("{i:>4}  {text}  [{}]\n", serves.join(", "))
    }
}
