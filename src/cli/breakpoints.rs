//! The tree file's `breakpoints:`, read as `run --view --break` patterns: each parsed and
//! matched against the tree's nodes, an error located where the entry is written. `validate`
//! checks them; `run --view` pauses at them.

use crate::plan::Plan;
use crate::spec::Diagnostic;
use crate::viewer::{BreakSpec, Monitor};

/// The tree file's breakpoints, or every entry that does not parse or matches no node.
pub(super) fn declared(plan: &Plan) -> Result<Vec<BreakSpec>, Vec<Diagnostic>> {
    let mut specs = Vec::new();
    let mut errors = Vec::new();
    for d in &plan.breakpoints {
        let checked = d
            .text
            .parse::<BreakSpec>()
            .and_then(|spec| Monitor::new(plan, std::slice::from_ref(&spec)).map(|_| spec));
        match checked {
            Ok(spec) => specs.push(spec),
            Err(reason) => {
                let mut e = Diagnostic::at(
                    &d.file,
                    d.line,
                    d.column,
                    format!("breakpoint {:?}: {reason}", d.text),
                );
                e.help = Some(format!(
                    "write a node path glob as `macrotree graph {}` or the monitor shows them, optionally ending in `@before` or `@after`",
                    plan.file
                ));
                errors.push(e);
            }
        }
    }
    if errors.is_empty() { Ok(specs) } else { Err(errors) }
}
