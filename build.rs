//! Bakes an rpath to the MuJoCo library folder into every executable of this package
//! (binary, tests, doctests, benches), so they run without LD_LIBRARY_PATH.
//! The folder comes from `MUJOCO_DYNAMIC_LINK_DIR`, which `.cargo/config.toml` sets to
//! `third_party/mujoco/lib` (filled by `tools/bootstrap`). Only this package's executables get
//! it: a crate that depends on macrotree adds its own (see docs/custom_nodes.md).

fn main() {
    println!("cargo:rerun-if-env-changed=MUJOCO_DYNAMIC_LINK_DIR");
    // Without the `sim` feature nothing links MuJoCo.
    if std::env::var_os("CARGO_FEATURE_SIM").is_none() {
        return;
    }
    match std::env::var("MUJOCO_DYNAMIC_LINK_DIR") {
        Ok(dir) => {
            if !std::path::Path::new(&dir).join("libmujoco.so").exists() {
                println!("cargo:warning=libmujoco.so not found in {dir}: run tools/bootstrap first");
            }
            println!("cargo:rustc-link-arg=-Wl,-rpath,{dir}");
        }
        Err(_) => println!(
            "cargo:warning=MUJOCO_DYNAMIC_LINK_DIR is not set: run cargo from the repository root (it reads .cargo/config.toml), or, in a crate that depends on macrotree, set it in that crate's .cargo/config.toml (docs/custom_nodes.md)"
        ),
    }
}
