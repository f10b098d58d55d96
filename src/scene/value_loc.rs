//! [`loc_at`]: where in a scene file a value under a path is, for located issues.

use crate::yaml::diag::Loc;
use crate::yaml::value::Value;

/// The location of the value at `path` under `v` (or `v`'s own when absent).
pub(super) fn loc_at(v: &Value, path: &[&str]) -> Loc {
    let mut cur = v;
    for k in path {
        match cur.get(k) {
            Some(next) => cur = next,
            None => break,
        }
    }
    cur.loc
}
