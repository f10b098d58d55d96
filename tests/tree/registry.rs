//! The registry of node kinds: the built-in kinds as entries like any other, and a user's
//! leaves flowing through parsing, validation, suggestions, schema, catalog, labels and the
//! runtime (physics-free here; `example_custom_leaf.rs` runs one on physics).

use std::sync::Arc;

use macrotree::actions::{Cell, MacroAction, Progress};
use macrotree::kinds::{Leaf, ObjectRef, ObjectRole};
use macrotree::plan::LeafId;
use macrotree::runtime::{LeafDriver, LeafOutcome, Selection, TreeRunner, TreeStatus};
use macrotree::world::World;
use macrotree::{App, Category, Params, Registry};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// `probe: {object, depth}`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
struct Probe {
    /// The object (a name or `{var}`).
    object: ObjectRef,
    /// How deep, metres.
    #[serde(deserialize_with = "macrotree::yaml::units::distance")]
    depth: f64,
    /// Shallowest allowed, metres. Default 0.
    #[serde(default, deserialize_with = "macrotree::yaml::units::distance")]
    min_depth: f64,
}

impl Params for Probe {
    const OBJECT_PARAMS: &'static [(&'static str, ObjectRole)] = &[("object", ObjectRole::Any)];
    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        vec![&mut self.object]
    }
    fn label(&self, kind: &str) -> Option<String> {
        Some(format!("{kind} {} {} m", self.object, self.depth))
    }
    fn timeout(&self) -> Option<f64> {
        Some(3.0)
    }
    fn validate(&self) -> Result<(), String> {
        if self.min_depth > self.depth {
            Err(format!(
                "`min_depth` ({} m) is more than `depth` ({} m)",
                self.min_depth, self.depth
            ))
        } else {
            Ok(())
        }
    }
}

/// `touching: {object}`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
struct Touching {
    /// The object (a name or `{var}`).
    object: ObjectRef,
}

impl Params for Touching {
    const OBJECT_PARAMS: &'static [(&'static str, ObjectRole)] = &[("object", ObjectRole::Block)];
    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        vec![&mut self.object]
    }
}

struct Idle;

impl MacroAction for Idle {
    fn start(&mut self, _: &mut Cell) -> Result<(), macrotree::Failure> {
        Ok(())
    }
    fn update(&mut self, _: &mut Cell) -> Progress {
        Progress::Done
    }
}

const PROBE_DOC: &str = "Probe an object.\n\nHalt: the arm holds where it is.\n\n```yaml\nprobe: {object: cube, depth: 0.01}\n```\n";
const TOUCHING_DOC: &str = "The gripper touches the object.\n\nHalt: nothing to halt (instantaneous).\n\n```yaml\ntouching: {object: cube}\n```\n";

fn app() -> App {
    let mut app = App::new();
    app.register_action("probe", PROBE_DOC, |_: &Probe| Box::new(Idle))
        .unwrap()
        .register_condition("touching", TOUCHING_DOC, |_: &World, _: &Touching| Ok(true))
        .unwrap();
    app
}

#[test]
fn the_built_in_kinds_are_registry_entries() {
    let r = Registry::builtin();
    assert_eq!(r.names().count(), 39);
    let count = |c| r.names_of(c).len();
    assert_eq!(
        [
            count(Category::Composite),
            count(Category::Decorator),
            count(Category::Action),
            count(Category::Runtime),
            count(Category::Condition)
        ],
        [6, 9, 8, 2, 14]
    );
    assert_eq!(r.get("grasp").map(|t| t.category()), Some(Category::Action));
    assert!(r.get("grasp").unwrap().doc().contains("```yaml"));
}

#[test]
fn registration_refuses_bad_names_duplicates_and_incomplete_docs() {
    let mut r = Registry::builtin();
    let e = r
        .declare_condition::<Touching>("reach", TOUCHING_DOC)
        .unwrap_err();
    assert_eq!(e.kind(), "registry");
    assert!(e.message().contains("already registered"), "{e}");
    let e = r
        .declare_condition::<Touching>("Touching!", TOUCHING_DOC)
        .unwrap_err();
    assert!(e.message().contains("not a valid node kind"), "{e}");
    let e = r
        .declare_condition::<Touching>("touching", "The gripper touches it.\n")
        .unwrap_err();
    assert!(e.message().contains("Halt"), "{e}");
    let e = r
        .declare_condition::<Touching>("touching", PROBE_DOC)
        .unwrap_err();
    assert!(e.message().contains("example that uses `touching:`"), "{e}");
    // Nothing was added by the refused calls.
    assert_eq!(r.names().count(), 39);
}

#[test]
fn custom_leaves_are_parsed_checked_and_suggested_like_built_in_ones() {
    let app = app();
    let plan = app
        .compile_str(
            "main: {sequence: {children: [{probe: {object: cube, depth: 0.02}}, {guard: {condition: {touching: {object: cube}}, child: {home: {}}}}]}}",
            "t.yaml",
        )
        .unwrap();
    let probe = plan.leaves[0].kind.params::<Probe>().expect("a probe");
    assert_eq!(probe.depth, 0.02);
    assert!(plan.leaves[1].kind.is_condition());
    assert_eq!(plan.nodes[1].label, "probe cube 0.02 m");
    assert_eq!(plan.nodes[1].category, Category::Action);
    assert_eq!(plan.nodes[3].label, "touching?");
    assert!(macrotree::plan::to_mermaid(&plan).contains("n3([\"touching?\"])"));

    let errors = |yaml: &str| app.compile_str(yaml, "t.yaml").unwrap_err().to_string();
    // A misspelled custom kind, and a misspelled parameter of one.
    let e = errors("main: {prob: {object: cube, depth: 0.02}}\n");
    assert!(
        e.contains("t.yaml:1:8") && e.contains("did you mean `probe`?"),
        "{e}"
    );
    let e = errors("main: {probe: {object: cube, deph: 0.02}}\n");
    assert!(
        e.contains("t.yaml:1:30") && e.contains("did you mean `depth`?"),
        "{e}"
    );
    // Range-checked with the crate's unit parsers, located at the value.
    let e = errors("main: {probe: {object: cube, depth: -1}}\n");
    assert!(e.contains("t.yaml:1:37"), "{e}");
    // The validation hook, reported at the node.
    let e = errors("main: {probe: {object: cube, depth: 0.01, min_depth: 0.02}}\n");
    assert!(e.contains("t.yaml:1:8"), "{e}");
    assert!(
        e.contains("`min_depth` (0.02 m) is more than `depth` (0.01 m)"),
        "{e}"
    );
    // Objects are checked against the scene; a guard accepts the custom condition only.
    let e = errors("main: {touching: {object: bwl}}\n");
    assert!(e.contains("unknown object `bwl`"), "{e}");
    let e = errors("main: {guard: {condition: {probe: {object: cube, depth: 0.1}}, child: {home: {}}}}\n");
    assert!(
        e.contains("touching"),
        "the expected conditions include the custom one: {e}"
    );
    // The built-in registry does not know them.
    let e = App::new()
        .compile_str("main: {touching: {object: cube}}\n", "t.yaml")
        .unwrap_err();
    assert_eq!(e.kind(), "invalid_tree");
}

#[test]
fn custom_leaves_are_in_the_catalog_and_the_schema() {
    let app = app();
    let catalog = app.registry().catalog();
    let probe = catalog.iter().find(|d| d.kind == "probe").unwrap();
    assert_eq!(probe.category, "action");
    assert_eq!(probe.summary, "Probe an object.");
    let depth = probe.params.iter().find(|p| p.name == "depth").unwrap();
    assert!(depth.required && depth.doc.contains("metres"), "{depth:?}");

    let schema = app.registry().json_schema();
    let validator = jsonschema::validator_for(&schema).unwrap();
    let tree = |yaml: &str| -> serde_json::Value { serde_saphyr::from_str(yaml).unwrap() };
    assert!(validator.is_valid(&tree(
        "main: {guard: {condition: {touching: {object: cube}}, child: {probe: {object: cube, depth: 0.01}}}}"
    )));
    assert!(!validator.is_valid(&tree("main: {probe: {object: cube, deep: 0.01}}")));
    // The built-in schema is unchanged by a user's registration.
    assert_eq!(
        Registry::builtin().json_schema(),
        macrotree::plan::Loader::default().registry().json_schema()
    );
}

/// Answers every leaf with Success, records the `object` each custom leaf was ticked with, and
/// selects `red`.
#[derive(Default)]
struct Recorder {
    seen: Vec<String>,
}

impl LeafDriver for Recorder {
    fn tick(&mut self, _: LeafId, leaf: &Leaf, _: bool) -> LeafOutcome {
        if let Some(p) = leaf.params::<Probe>() {
            self.seen.push(format!("probe {}", p.object));
        }
        if let Some(p) = leaf.params::<Touching>() {
            self.seen.push(format!("touching {}", p.object));
        }
        LeafOutcome::Success
    }
    fn halt(&mut self, _: LeafId, _: &Leaf) {}
    fn select_object(
        &mut self,
        _: &macrotree::world::query::Query,
    ) -> Result<Option<Selection>, macrotree::Failure> {
        Ok(Some(Selection {
            object: "cube".into(),
            destination: None,
        }))
    }
}

#[test]
fn variables_in_custom_leaves_are_resolved_before_each_tick() {
    let plan = app()
        .compile_str(
            "main: {sequence: {children: [{select: {as: it}}, {probe: {object: \"{it}\", depth: 0.01}}, {touching: {object: \"{it}\"}}]}}",
            "t.yaml",
        )
        .unwrap();
    let mut runner = TreeRunner::new(Arc::new(plan));
    let mut driver = Recorder::default();
    let mut status = TreeStatus::Running;
    for k in 0..10 {
        status = runner.tick(k as f64 * 0.1, 0.1, &mut driver);
        if status != TreeStatus::Running {
            break;
        }
    }
    assert_eq!(status, TreeStatus::Success);
    assert_eq!(driver.seen, ["probe cube", "touching cube"]);
}

/// `level: {max_tilt, min_tilt}`: a condition whose own check names the parameter it is about.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
struct Level {
    /// Largest tilt, radians (or `deg(..)`). Default deg(5).
    #[serde(default = "five_degrees")]
    max_tilt: macrotree::yaml::units::Angle,
    /// Smallest tilt, radians (or `deg(..)`). Default deg(-7.5).
    #[serde(default = "minus_seven_and_a_half_degrees")]
    min_tilt: macrotree::yaml::units::Angle,
}

fn five_degrees() -> macrotree::yaml::units::Angle {
    macrotree::yaml::units::Angle(5f64.to_radians())
}

fn minus_seven_and_a_half_degrees() -> macrotree::yaml::units::Angle {
    macrotree::yaml::units::Angle((-7.5f64).to_radians())
}

impl Params for Level {
    fn validate_fields(&self) -> Result<(), macrotree::ParamError> {
        if self.max_tilt.0 > 0.5 {
            return Err(macrotree::ParamError::at("max_tilt", "must be at most 0.5 rad"));
        }
        if self.min_tilt.0 > self.max_tilt.0 {
            return Err("`min_tilt` is more than `max_tilt`".into());
        }
        Ok(())
    }
}

const LEVEL_DOC: &str = "The arm is level.\n\nHalt: nothing to halt (instantaneous).\n\n```yaml\nlevel: {max_tilt: deg(3)}\n```\n";

#[test]
fn validate_fields_errors_point_at_the_value_they_name() {
    let mut app = App::new();
    app.register_condition("level", LEVEL_DOC, |_: &World, _: &Level| Ok(true))
        .unwrap();
    let errors = |yaml: &str| app.compile_str(yaml, "t.yaml").unwrap_err().to_string();
    // Named field, written in the file: at its value.
    let e = errors("main: {level: {max_tilt: deg(40)}}\n");
    assert!(e.contains("t.yaml:1:26"), "{e}");
    assert!(e.contains("`max_tilt` must be at most 0.5 rad"), "{e}");
    // Named through a subtree argument: still the value (where the subtree uses it).
    let e = errors(
        "main: {subtree: {ref: s, args: {t: deg(40)}}}\nsubtrees:\n  s:\n    params: {t: ~}\n    root: {level: {max_tilt: $t}}\n",
    );
    assert!(e.contains("`max_tilt` must be at most 0.5 rad"), "{e}");
    assert!(!e.contains("t.yaml:5:12"), "not at the node kind: {e}");
    // No field named (a plain message): at the node, as before.
    let e = errors("main: {level: {min_tilt: deg(10)}}\n");
    assert!(e.contains("t.yaml:1:8"), "{e}");
    assert!(e.contains("`min_tilt` is more than `max_tilt`"), "{e}");

    // The catalog shows angle defaults as users write them.
    let catalog = app.registry().catalog();
    let level = catalog.iter().find(|d| d.kind == "level").unwrap();
    let default = |name: &str| {
        level
            .params
            .iter()
            .find(|p| p.name == name)
            .and_then(|p| p.default.clone())
    };
    assert_eq!(default("max_tilt").as_deref(), Some("deg(5)"));
    assert_eq!(default("min_tilt").as_deref(), Some("deg(-7.5)"));
}

/// `lift_block: {block, height}` — an object parameter whose key is none of the built-in ones.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
struct LiftBlock {
    /// The block (a name or `{var}`).
    block: ObjectRef,
    /// Where to, a container (a name or `{var}`).
    into: ObjectRef,
}

impl Params for LiftBlock {
    const OBJECT_PARAMS: &'static [(&'static str, ObjectRole)] =
        &[("block", ObjectRole::Block), ("into", ObjectRole::Container)];
    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        vec![&mut self.block, &mut self.into]
    }
}

const LIFT_BLOCK_DOC: &str = "Lift a block into a container.\n\nHalt: the arm holds where it is.\n\n```yaml\nlift_block: {block: cube, into: bowl}\n```\n";

/// Bug (issue 18): the loader guessed which parameters name objects from their keys (`object`,
/// `support`, `container`, `target`, `to`), so `block:` in a custom leaf was never checked against
/// the scene and a misspelled block name only failed when the leaf ran.
#[test]
fn a_custom_leafs_block_parameter_is_checked_against_the_scene() {
    let mut app = App::new();
    app.register_action("lift_block", LIFT_BLOCK_DOC, |_: &LiftBlock| Box::new(Idle))
        .unwrap();
    let ok = app.compile_str("main: {lift_block: {block: cube, into: bowl}}\n", "t.yaml");
    assert!(ok.is_ok(), "{}", ok.unwrap_err());
    let e = app
        .compile_str("main: {lift_block: {block: cueb, into: bowl}}\n", "t.yaml")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("t.yaml:1:28") && e.contains("unknown object `cueb`"),
        "{e}"
    );
    assert!(e.contains("did you mean `cube`?"), "{e}");
    // The declared role is checked too: a container where a block belongs.
    let e = app
        .compile_str("main: {lift_block: {block: bowl, into: bowl}}\n", "t.yaml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("t.yaml:1:28") && e.contains("a block"), "{e}");
    let e = app
        .compile_str("main: {lift_block: {block: cube, into: cube}}\n", "t.yaml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("t.yaml:1:40") && e.contains("a container"), "{e}");
}

/// What a kind does not declare is not guessed: an `object:` key of a custom leaf whose
/// parameter type declares no object parameters is not checked against the scene.
#[test]
fn object_parameters_come_from_the_declaration_not_from_key_names() {
    let registry = Registry::builtin();
    let roles = |k: &str| registry.get(k).unwrap().object_params().to_vec();
    assert_eq!(
        roles("in"),
        [
            ("object", ObjectRole::Block),
            ("container", ObjectRole::Container)
        ]
    );
    assert_eq!(roles("reach"), [("target", ObjectRole::Any)]);
    assert_eq!(roles("home"), []);
    let mut app = App::new();
    app.register_action(
        "unchecked",
        LIFT_BLOCK_DOC.replace("lift_block", "unchecked").leak(),
        |_: &Unchecked| Box::new(Idle),
    )
    .unwrap();
    assert!(
        app.compile_str("main: {unchecked: {object: nowhere}}\n", "t.yaml")
            .is_ok()
    );
}

/// `unchecked: {object}`, declaring no object parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
struct Unchecked {
    /// Any text.
    object: String,
}

impl Params for Unchecked {}
