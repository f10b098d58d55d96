//! Links the extension against the MuJoCo library of the pinned `mujoco==3.17.0` wheel at run
//! time: the wheel installs `mujoco/libmujoco.so.3.17.0` beside `macrotree/` in site-packages,
//! so the extension (`macrotree/_native.abi3.so`) finds it through `$ORIGIN/../mujoco`. At build
//! time the library comes from `MUJOCO_DYNAMIC_LINK_DIR` (third_party/mujoco/lib, filled by
//! tools/bootstrap), which the repository's `.cargo/config.toml` sets.

fn main() {
    println!("cargo:rustc-link-arg-cdylib=-Wl,-rpath,$ORIGIN/../mujoco");
}
