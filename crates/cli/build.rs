//! Links the `hydrocyl` binary as a fixed-address executable (not PIE) on
//! Linux with glibc: a PIE's loader applies ~9,800 relocations at every
//! start, writing ~40 pages of `.data.rel.ro` (a page fault each) and
//! reading the relocation table; a fixed-address binary needs none of it.
//! Only the binaries are linked so (`rustc-link-arg-bins`): the tests, the
//! Python module and the proc-macros are not touched.

fn main() {
    let os = std::env::var("CARGO_CFG_TARGET_OS").unwrap_or_default();
    let env = std::env::var("CARGO_CFG_TARGET_ENV").unwrap_or_default();
    if os == "linux" && env == "gnu" {
        println!("cargo:rustc-link-arg-bins=-no-pie");
    }
    println!("cargo:rerun-if-changed=build.rs");
}
