//! A missing MeshCat bundle gives a clear error naming tools/bootstrap (own test binary: it
//! sets `MACROTREE_MESHCAT` for the whole process).

use macrotree::sim::Scene;
use macrotree::viewer::{LiveViewer, Recorder, ViewerError, ViewerOptions, page};

#[test]
fn a_missing_bundle_says_to_run_tools_bootstrap() {
    let missing =
        std::env::temp_dir().join(format!("macrotree-no-bundle-{}/main.min.js", std::process::id()));
    // SAFETY: this test binary has a single test, so no other thread reads the environment.
    unsafe { std::env::set_var(page::BUNDLE_ENV, &missing) };
    assert_eq!(page::bundle_path(), missing);
    let scene = Scene::load().unwrap();
    let opts = ViewerOptions {
        port: 0,
        ..ViewerOptions::default()
    };
    let err = LiveViewer::start(&scene.model, &opts).unwrap_err();
    assert!(
        matches!(&err, ViewerError::BundleMissing { path } if path == &missing),
        "{err:?}"
    );
    let text = err.to_string();
    assert!(
        text.contains("tools/bootstrap") && text.contains("main.min.js"),
        "{text}"
    );

    let rec = Recorder::new(&scene.model);
    let out = std::env::temp_dir().join(format!("macrotree-no-bundle-{}.html", std::process::id()));
    let err = rec.write(&out).unwrap_err();
    assert_eq!(err.kind(), std::io::ErrorKind::NotFound);
    assert!(err.to_string().contains("tools/bootstrap"), "{err}");
    assert!(!out.exists());
}
