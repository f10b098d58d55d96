//! Bakes an rpath to the MuJoCo library folder into the fuzz binaries, as the main package's
//! build.rs does for its own executables (a dependency's link args do not reach dependents):
//! macrotree links libmujoco.so even though the loader never calls it.
//! `MUJOCO_DYNAMIC_LINK_DIR` comes from the repository's `.cargo/config.toml`, which cargo reads
//! when it is run from the repository root or from `fuzz/`.

fn main() {
    println!("cargo:rerun-if-env-changed=MUJOCO_DYNAMIC_LINK_DIR");
    match std::env::var("MUJOCO_DYNAMIC_LINK_DIR") {
        Ok(dir) => println!("cargo:rustc-link-arg=-Wl,-rpath,{dir}"),
        Err(_) => println!(
            "cargo:warning=MUJOCO_DYNAMIC_LINK_DIR is not set: run cargo fuzz from the repository root"
        ),
    }
}
