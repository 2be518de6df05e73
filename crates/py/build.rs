//! The extension finds libmujoco where the `mujoco` wheel it depends on installs it, beside
//! it in site-packages, with no LD_LIBRARY_PATH.

fn main() {
    println!("cargo:rustc-cdylib-link-arg=-Wl,-rpath,$ORIGIN/../mujoco");
}
