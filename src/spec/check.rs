//! Checks of what a tree names: blackboard variables against the `select`s and `for_each`s that
//! write them (always), and object names against a scene (when the scene is known). Every
//! problem is located at the name as written, with a did-you-mean.

use serde::Serialize;

use crate::kinds::leaves::Select;
use crate::kinds::objects::{ObjectRef, ObjectRole};
use crate::scene::{ObjectKind, SceneSpec};
use crate::yaml::diag::{Issue, Loc};
use crate::yaml::suggest::{closest, did_you_mean};

/// How a leaf names an object.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Named {
    /// By name or variable.
    Ref(ObjectRef),
    /// The legacy `cube` (the block called `cube`, else the scene's only block).
    LegacyCube,
    /// The legacy `bowl` (the container called `bowl`, else the scene's only container).
    LegacyBowl,
}

/// One place where a leaf names an object.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectUse {
    /// The name or variable.
    pub reference: Named,
    /// What it must be.
    pub role: ObjectRole,
    /// Where it is written.
    pub loc: Loc,
    /// If it came from a subtree argument, where the `$param` was used.
    pub via: Option<Loc>,
    /// The leaf kind (`reach`, `in`, …).
    pub leaf: String,
}

/// The type of a blackboard variable: what kind of object it holds.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum VarType {
    /// Objects of this kind.
    Kind(ObjectKind),
    /// A goal's destination: a container, a block, or the spot of an `at` goal.
    Destination,
}

impl VarType {
    fn fits(self, role: ObjectRole) -> bool {
        match (self, role) {
            (_, ObjectRole::Any) => true,
            (VarType::Kind(k), r) => r.accepts(k),
            // An `at` goal's destination is its spot.
            (VarType::Destination, ObjectRole::Spot) => true,
            (VarType::Destination, _) => false,
        }
    }

    fn name(self) -> &'static str {
        match self {
            VarType::Kind(ObjectKind::Block) => "a block",
            VarType::Kind(ObjectKind::Container) => "a container",
            VarType::Kind(ObjectKind::Obstacle) => "an obstacle",
            VarType::Destination => "a goal destination (a container, a block or a spot)",
        }
    }
}

/// One place where a variable is written.
#[derive(Clone, Debug, PartialEq)]
pub struct VarDef {
    /// The variable.
    pub name: String,
    /// What it holds.
    pub ty: VarType,
    /// Where its name is written (`as:`/`goal_as:`).
    pub loc: Loc,
}

impl VarDef {
    /// The variables a select writes: `as` (the object) and `goal_as` (its destination).
    pub fn from_select(s: &Select, loc: Loc, goal_loc: Option<Loc>) -> Vec<VarDef> {
        let mut out = vec![VarDef {
            name: s.var.clone(),
            ty: VarType::Kind(s.kind.kind()),
            loc,
        }];
        if let Some(g) = &s.goal_var {
            out.push(VarDef {
                name: g.clone(),
                ty: VarType::Destination,
                loc: goal_loc.unwrap_or(loc),
            });
        }
        out
    }
}

/// Variables used but never written, used as the wrong type, or written with two types.
pub fn check_vars(uses: &[ObjectUse], defs: &[VarDef], describe: impl Fn(Loc) -> String) -> Vec<Issue> {
    let mut issues = Vec::new();
    for (i, d) in defs.iter().enumerate() {
        if let Some(first) = defs[..i].iter().find(|e| e.name == d.name && e.ty != d.ty) {
            issues.push(
                Issue::new(
                    d.loc,
                    format!("variable `{}` is written as {} here", d.name, d.ty.name()),
                )
                .label(format!("but as {} at {}", first.ty.name(), describe(first.loc)))
                .help("a variable keeps one type: use another name for one of them"),
            );
        }
    }
    for u in uses {
        let Named::Ref(ObjectRef::Var(v)) = &u.reference else {
            continue;
        };
        let written: Vec<&VarDef> = defs.iter().filter(|d| d.name == v.as_str()).collect();
        let mut issue = if written.is_empty() {
            let names: Vec<&str> = defs.iter().map(|d| d.name.as_str()).collect();
            Issue::new(u.loc, format!("undefined variable `{{{v}}}` in `{}`", u.leaf))
                .label("no `select` or `for_each` writes it")
                .maybe_help(closest(v, names.iter().copied()).map(|c| format!("did you mean `{{{c}}}`?")))
                .help_or(format!("write it first, e.g. `select: {{as: {v}, kind: block}}`"))
        } else if let Some(d) = written.iter().find(|d| !d.ty.fits(u.role)) {
            Issue::new(
                u.loc,
                format!(
                    "`{{{v}}}` holds {}, but `{}` needs {} here",
                    d.ty.name(),
                    u.leaf,
                    u.role.name()
                ),
            )
            .label(format!("written at {}", describe(d.loc)))
        } else {
            continue;
        };
        if let Some(via) = u.via {
            issue = issue.note(format!(
                "this value is a subtree argument, used at {}",
                describe(via)
            ));
        }
        issues.push(issue);
    }
    issues
}

/// Checks every object and spot a tree names against `scene`: the name exists, it is the right
/// kind of object (or a spot where a spot fits), and the legacy names `cube`/`bowl` stand for
/// exactly one object.
pub fn check_scene(uses: &[ObjectUse], scene: &SceneSpec, describe: impl Fn(Loc) -> String) -> Vec<Issue> {
    let mut issues = Vec::new();
    for u in uses {
        let issue = match &u.reference {
            Named::Ref(ObjectRef::Var(_)) => continue,
            Named::Ref(ObjectRef::Name(n)) => match (scene.object(n.as_str()), scene.spot(n.as_str())) {
                (Some(o), _) if !u.role.accepts(o.kind()) => Issue::new(
                    u.loc,
                    format!(
                        "`{n}` is a {}, but `{}` needs {} here",
                        o.kind(),
                        u.leaf,
                        u.role.name()
                    ),
                ),
                (Some(_), _) => continue,
                (None, Some(_)) if !u.role.accepts_spot() => Issue::new(
                    u.loc,
                    format!("`{n}` is a spot, but `{}` needs {} here", u.leaf, u.role.name()),
                ),
                (None, Some(_)) => continue,
                (None, None) => unknown_name(u, n.as_str(), scene),
            },
            Named::LegacyCube if scene.legacy_cube().is_none() => {
                legacy_issue(u, scene, "cube", ObjectKind::Block)
            }
            Named::LegacyBowl if scene.legacy_bowl().is_none() => {
                legacy_issue(u, scene, "bowl", ObjectKind::Container)
            }
            _ => continue,
        };
        let issue = match u.via {
            Some(via) => issue.note(format!(
                "this value is a subtree argument, used at {}",
                describe(via)
            )),
            None => issue,
        };
        issues.push(issue);
    }
    issues
}

/// A name that is neither an object nor a spot of `scene`: what was expected there, with a
/// did-you-mean among the names that would fit.
fn unknown_name(u: &ObjectUse, n: &str, scene: &SceneSpec) -> Issue {
    let objects = scene.objects.iter().map(|o| o.name.as_str());
    let spots = scene.spots.iter().map(|s| s.name.as_str());
    let (what, fitting): (&str, Vec<&str>) = match u.role {
        ObjectRole::Spot => ("spot", spots.collect()),
        ObjectRole::Any => ("target", objects.chain(spots).collect()),
        _ => ("object", objects.collect()),
    };
    let hint = did_you_mean(n, fitting.iter().copied()).map_or(String::new(), |h| format!(" ({h})"));
    let listed = if fitting.is_empty() {
        format!("scene `{}` has none", scene.name)
    } else {
        format!("scene `{}` has {}", scene.name, fitting.join(", "))
    };
    let expected = match u.role {
        ObjectRole::Spot => format!("expected a spot ({listed}) or a variable `{{name}}`"),
        ObjectRole::Any => {
            format!("expected an object or a spot ({listed}), a variable `{{name}}` or `[x, y, z]`")
        }
        _ => format!("expected an object ({listed}) or a variable `{{name}}`"),
    };
    let help = if u.role == ObjectRole::Spot {
        "name a spot of the scene (its `spots:`), or run the tree on another scene with `--scene FILE`"
    } else {
        "name an object of the scene, or run the tree on another scene with `--scene FILE`"
    };
    Issue::new(u.loc, format!("unknown {what} `{n}` in `{}`{hint}", u.leaf))
        .label(expected)
        .help(help)
}

fn legacy_issue(u: &ObjectUse, scene: &SceneSpec, legacy: &str, kind: ObjectKind) -> Issue {
    let of_kind: Vec<&str> = scene
        .of_kind(kind)
        .map(|i| scene.objects[i].name.as_str())
        .collect();
    let what = if of_kind.is_empty() {
        format!("it has no {kind}")
    } else {
        format!("it has {} {kind}s: {}", of_kind.len(), of_kind.join(", "))
    };
    Issue::new(
        u.loc,
        format!(
            "`{}` refers to the scene's only {kind} (`{legacy}`), but scene `{}` is ambiguous: {what}",
            u.leaf, scene.name
        ),
    )
    .help(format!(
        "name the object (`object: {}`) or select one into a variable (`select: {{as: x}}`, then `{{x}}`)",
        of_kind.first().copied().unwrap_or("NAME")
    ))
}
