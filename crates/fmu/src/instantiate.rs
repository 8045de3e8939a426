//! From an FMU's resources to a [`Slave`]: where `fmuResourceLocation`
//! points, the rig file read there, the GUID check and why it fails (the
//! rig or the build differs), and the build check the packager makes on a
//! slave library ([`library_guid`] through [`hydrocyl_fmu_guid`]).
#![allow(unsafe_code, clippy::missing_safety_doc)]

use crate::ffi::string;
use crate::model_description::{guid, rig_digest, variables_digest, DIGESTS};
use crate::slave::Slave;
use crate::variables::Variables;
use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::panic::catch_unwind;
use std::path::{Path, PathBuf};

/// The folder of `fmuResourceLocation`: a `file:` URI (`file:///a/b`,
/// `file://localhost/a/b`, `file:/a/b`, percent-encoded) or a plain path.
pub fn resource_dir(location: &str) -> Result<PathBuf, String> {
    let Some(rest) = location.strip_prefix("file:") else {
        return Ok(PathBuf::from(location));
    };
    let path = match rest.strip_prefix("//") {
        Some(auth) => {
            let slash = auth.find('/').unwrap_or(auth.len());
            match &auth[..slash] {
                "" | "localhost" => &auth[slash..],
                host => {
                    return Err(format!(
                        "fmuResourceLocation `{location}`: remote host `{host}`"
                    ))
                }
            }
        }
        None => rest,
    };
    if !path.starts_with('/') {
        return Err(format!(
            "fmuResourceLocation `{location}` is not an absolute file URI"
        ));
    }
    let bytes: Vec<u8> = percent_encoding::percent_decode_str(path).collect();
    use std::os::unix::ffi::OsStringExt;
    Ok(PathBuf::from(std::ffi::OsString::from_vec(bytes)))
}

/// The value of attribute `name` of the first element of `xml` that has
/// it after `from` (the model description is ours: attributes in double
/// quotes, nothing escaped in those read here).
fn attribute<'a>(xml: &'a str, from: &str, name: &str) -> Option<&'a str> {
    let at = xml.find(from)?;
    let key = format!(" {name}=\"");
    let start = at + xml[at..].find(&key)? + key.len();
    let end = xml[start..].find('"')?;
    Some(&xml[start..start + end])
}

/// Why the GUID the host gives (the one in `modelDescription.xml`) is not
/// the one this library computes for `text` (the FMU's `resources/rig.json`
/// at `rig`) and the variables it makes of it (`made`: the variables, or
/// why it cannot make them). The GUID covers this crate's version, the
/// variable list and the rig's text; the model description beside the
/// `resources` folder names the version that packaged the FMU
/// (`generationTool`) and holds the digests of the rig's text and of the
/// variable list as packaged, which tell which of them differs.
fn why_guid_differs(rig: &Path, text: &str, made: Result<&Variables, &str>) -> String {
    let ours = env!("CARGO_PKG_VERSION");
    let rebuild = "rebuild with `cargo build -p hydrocyl-fmu -p hydrocyl-cli` and export the rig again (`hydrocyl fmu`)";
    let xml = rig
        .parent()
        .and_then(Path::parent)
        .and_then(|root| std::fs::read_to_string(root.join("modelDescription.xml")).ok());
    let xml = xml.as_deref().unwrap_or("");
    let version = attribute(xml, "<fmiModelDescription", "generationTool")
        .and_then(|t| t.strip_prefix("hydrocyl "));
    let digests = (
        attribute(xml, &format!("<{DIGESTS} "), "rig"),
        attribute(xml, &format!("<{DIGESTS} "), "variables"),
    );
    match (version, digests) {
        (Some(v), _) if v != ours => format!(
            "the FMU was packaged by hydrocyl {v} (modelDescription.xml), this library is hydrocyl {ours}: {rebuild}"
        ),
        (_, (Some(r), _)) if r != rig_digest(text) => format!(
            "the rig differs: resources/rig.json is not the rig this FMU was packaged with (edited after the export; the library is the same build as far as the rig can tell): export the edited rig again (`hydrocyl fmu`), or set its parameters through the FMU's variables{}",
            made.err().map(|e| format!("; the edited rig: {e}")).unwrap_or_default()
        ),
        (_, (Some(_), Some(vd))) => match made {
            Err(e) => format!(
                "the build differs: resources/rig.json is the rig packaged, but this library (another build than the one that packaged the FMU) cannot read it: {e}; {rebuild}"
            ),
            Ok(vars) if variables_digest(vars) != vd => format!(
                "the build differs: resources/rig.json is the rig packaged, but this library is another build than the one that packaged the FMU: it makes other variables of the rig (value references would reach the wrong parameters); {rebuild}"
            ),
            Ok(_) => "the rig and the variables are those packaged: the GUID given is not the one in modelDescription.xml".into(),
        },
        _ => format!(
            "resources/rig.json differs from the rig the FMU was packaged with (edited after the export?), or this library is another build than the one that packaged the FMU (hydrocyl {ours}; the model description holds no digests to tell which): the GUID covers both{}",
            made.err().map(|e| format!("; the rig: {e}")).unwrap_or_default()
        ),
    }
}

/// The slave of the FMU whose resources are at `location`, if the GUID the
/// host gives is the one this library computes for its rig.
pub(crate) fn instantiate(guid_given: &str, location: Option<&str>) -> Result<Slave, String> {
    let location = location.ok_or("no fmuResourceLocation: the rig is in resources/rig.json")?;
    let path = resource_dir(location)?.join("rig.json");
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let slave = serde_json::from_str(&text)
        .map_err(|e| format!("not valid JSON: {e}"))
        .and_then(Slave::new);
    let expected = slave
        .as_ref()
        .map(|s| guid(&text, s.variables()))
        .map_err(String::as_str);
    if expected.as_deref() != Ok(guid_given) {
        let why = why_guid_differs(
            &path,
            &text,
            slave.as_ref().map(Slave::variables).map_err(String::as_str),
        );
        return Err(match expected {
            Ok(expected) => format!(
                "fmuGUID {guid_given} does not match this library and {} ({expected}): {why}",
                path.display()
            ),
            Err(_) => format!(
                "fmuGUID {guid_given}: this library cannot compute the GUID of {}: {why}",
                path.display()
            ),
        });
    }
    slave
}

/// The size of the buffer [`library_guid`] hands to [`hydrocyl_fmu_guid`].
const GUID_BUFFER: usize = 4096;

/// hydrocyl's own entry point (not FMI), for the packager: writes into
/// `out` (`size` bytes, NUL-terminated, truncated to fit) the GUID this
/// library computes for an FMU whose `resources/rig.json` holds the
/// NUL-terminated `rig_text`, and returns 0; when it cannot read the rig,
/// writes why and returns 1; -1 on a null pointer. `hydrocyl fmu` packages
/// a library only if its GUID is the packager's ([`library_guid`]).
#[no_mangle]
pub unsafe extern "C" fn hydrocyl_fmu_guid(
    rig_text: *const c_char,
    out: *mut c_char,
    size: usize,
) -> c_int {
    if rig_text.is_null() || out.is_null() || size == 0 {
        return -1;
    }
    let text = unsafe { CStr::from_ptr(rig_text) }
        .to_string_lossy()
        .into_owned();
    let result = catch_unwind(|| {
        let rig = serde_json::from_str(&text).map_err(|e| format!("not valid JSON: {e}"))?;
        Slave::new(rig).map(|s| guid(&text, s.variables()))
    })
    .unwrap_or_else(|_| Err("internal error (panic)".into()));
    let (code, msg) = match result {
        Ok(g) => (0, g),
        Err(e) => (1, e),
    };
    let bytes = msg.replace('\0', " ").into_bytes();
    let n = bytes.len().min(size - 1);
    unsafe {
        std::ptr::copy_nonoverlapping(bytes.as_ptr(), out.cast::<u8>(), n);
        *out.add(n) = 0;
    }
    code
}

/// The GUID the slave library at `library` computes for the rig `rig_text`
/// (through its [`hydrocyl_fmu_guid`]), or why there is none: the file
/// does not load as a library, has no `hydrocyl_fmu_guid` (a build older
/// than it), or cannot read the rig. The library stays loaded (unloading a
/// Rust library can leave its thread-local destructors dangling).
pub fn library_guid(library: &Path, rig_text: &str) -> Result<String, String> {
    use std::os::unix::ffi::OsStrExt;
    let one_line = |s: String| s.split_whitespace().collect::<Vec<_>>().join(" ");
    let path = CString::new(library.as_os_str().as_bytes())
        .map_err(|_| "its path holds a NUL byte".to_string())?;
    let text = CString::new(rig_text).map_err(|_| "the rig's text holds a NUL byte".to_string())?;
    let handle = unsafe { libc::dlopen(path.as_ptr(), libc::RTLD_NOW | libc::RTLD_LOCAL) };
    if handle.is_null() {
        let why = unsafe { string(libc::dlerror()) }.unwrap_or_default();
        return Err(one_line(format!("it does not load as a library: {why}")));
    }
    let sym = unsafe { libc::dlsym(handle, c"hydrocyl_fmu_guid".as_ptr()) };
    if sym.is_null() {
        return Err("it has no hydrocyl_fmu_guid: a build older than this hydrocyl's".to_string());
    }
    type GuidFn = unsafe extern "C" fn(*const c_char, *mut c_char, usize) -> c_int;
    let f: GuidFn = unsafe { std::mem::transmute::<*mut c_void, GuidFn>(sym) };
    let mut buf = vec![0 as c_char; GUID_BUFFER];
    let code = unsafe { f(text.as_ptr(), buf.as_mut_ptr(), buf.len()) };
    let msg = unsafe { string(buf.as_ptr()) }.unwrap_or_default();
    match code {
        0 => Ok(msg),
        _ => Err(one_line(format!("it cannot read this rig: {msg}"))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model_description::model_description;

    /// An unpacked FMU of leaney-moog: its `resources/rig.json` as packaged
    /// and, unless `tool` is None, a `modelDescription.xml` naming that
    /// generation tool (with the digests when `digests`); returns the
    /// folder, the resource URI and the GUID.
    fn unpacked(tool: Option<&str>, digests: bool) -> (tempfile::TempDir, String, String) {
        let dir = tempfile::tempdir().unwrap();
        let res = dir.path().join("resources");
        std::fs::create_dir(&res).unwrap();
        let rig = hydrocyl_system::rig::preset("leaney-moog").unwrap();
        let text = serde_json::to_string_pretty(&rig).unwrap();
        std::fs::write(res.join("rig.json"), &text).unwrap();
        let vars = Variables::of(&rig).unwrap();
        let g = guid(&text, &vars);
        if let Some(tool) = tool {
            let mut xml = model_description(&vars, "leaney-moog", "a rig", &text)
                .replace(&format!("hydrocyl {}", env!("CARGO_PKG_VERSION")), tool);
            if !digests {
                let (a, b) = (
                    xml.find("  <VendorAnnotations>").unwrap(),
                    xml.find("  <ModelVariables>").unwrap(),
                );
                xml.replace_range(a..b, "");
            }
            std::fs::write(dir.path().join("modelDescription.xml"), xml).unwrap();
        }
        let uri = format!("file://{}", res.display());
        (dir, uri, g)
    }

    fn edit_rig(dir: &tempfile::TempDir) {
        let path = dir.path().join("resources").join("rig.json");
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::write(&path, text.replace("100.0", "50.0")).unwrap();
    }

    #[test]
    fn an_edited_rig_file_is_refused_as_such() {
        let ours = format!("hydrocyl {}", env!("CARGO_PKG_VERSION"));
        let (dir, uri, g) = unpacked(Some(&ours), true);
        assert!(instantiate(&g, Some(&uri)).is_ok());
        edit_rig(&dir);
        let e = instantiate(&g, Some(&uri)).err().unwrap();
        assert!(
            e.contains(
                "the rig differs: resources/rig.json is not the rig this FMU was packaged with"
            ),
            "{e}"
        );
        assert!(
            !e.contains("version") && !e.contains("build differs"),
            "{e}"
        );
    }

    /// The same rig, a library that makes other variables of it (another
    /// build): the message says the build differs, not the rig.
    #[test]
    fn another_build_is_named() {
        let ours = format!("hydrocyl {}", env!("CARGO_PKG_VERSION"));
        let (dir, uri, g) = unpacked(Some(&ours), true);
        // the packager's variables had one more parameter than this library's
        let md = dir.path().join("modelDescription.xml");
        let xml = std::fs::read_to_string(&md).unwrap();
        let vd = attribute(&xml, "<Digests ", "variables")
            .unwrap()
            .to_string();
        std::fs::write(
            &md,
            xml.replace(&vd, "{00000000-0000-0000-0000-000000000002}"),
        )
        .unwrap();
        let e = instantiate("{00000000-0000-0000-0000-000000000003}", Some(&uri))
            .err()
            .unwrap();
        assert!(
            e.contains("the build differs")
                && e.contains("cargo build -p hydrocyl-fmu -p hydrocyl-cli"),
            "{e}"
        );
        assert!(!e.contains("rig differs"), "{e}");
        // the GUID itself still opens the FMU
        assert!(instantiate(&g, Some(&uri)).is_ok());
    }

    #[test]
    fn another_version_is_named() {
        let (_dir, uri, _) = unpacked(Some("hydrocyl 0.0.0-old"), true);
        // the GUID in such an FMU is that version's
        let e = instantiate("{00000000-0000-0000-0000-000000000001}", Some(&uri))
            .err()
            .unwrap();
        assert!(
            e.contains("packaged by hydrocyl 0.0.0-old")
                && e.contains(&format!(
                    "this library is hydrocyl {}",
                    env!("CARGO_PKG_VERSION")
                )),
            "{e}"
        );
    }

    #[test]
    fn without_digests_both_causes_are_named() {
        let ours = format!("hydrocyl {}", env!("CARGO_PKG_VERSION"));
        for tool in [None, Some(ours.as_str())] {
            let (dir, uri, g) = unpacked(tool, false);
            edit_rig(&dir);
            let e = instantiate(&g, Some(&uri)).err().unwrap();
            assert!(
                e.contains("differs from the rig the FMU was packaged with")
                    && e.contains("another build"),
                "{e}"
            );
        }
    }

    /// The packager's check of a library: a file that does not load, and a
    /// library without `hydrocyl_fmu_guid` (a proc-macro library of this
    /// build's dependencies, beside the test binary), are named as such.
    #[test]
    fn a_library_without_the_guid_function_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let fake = dir.path().join("fake.so");
        std::fs::write(&fake, b"\x7fELF not a library fmi2DoStep").unwrap();
        let e = library_guid(&fake, "{}").unwrap_err();
        assert!(
            e.starts_with("it does not load as a library") && !e.contains('\n'),
            "{e}"
        );
        let other = crate::test_support::foreign_library();
        let e = library_guid(&other, "{}").unwrap_err();
        assert!(e.contains("no hydrocyl_fmu_guid"), "{e}");
    }

    /// The library's own entry point: the GUID of a rig, or why there is none.
    #[test]
    fn the_guid_entry_point_gives_the_guid_or_why_not() {
        let rig = hydrocyl_system::rig::preset("leaney-moog").unwrap();
        let text = serde_json::to_string_pretty(&rig).unwrap();
        let call = |t: &str, size: usize| {
            let t = CString::new(t).unwrap();
            let mut buf = vec![0 as c_char; size];
            let code = unsafe { hydrocyl_fmu_guid(t.as_ptr(), buf.as_mut_ptr(), size) };
            (code, unsafe { string(buf.as_ptr()) }.unwrap())
        };
        let (code, g) = call(&text, GUID_BUFFER);
        assert_eq!((code, g), (0, guid(&text, &Variables::of(&rig).unwrap())));
        let (code, e) = call("{\"kind\": 3}", GUID_BUFFER);
        assert!(code == 1 && e.contains("kind"), "{e}");
        let (code, e) = call("not json", 8);
        assert!(code == 1 && e.len() == 7, "{e}");
    }
}
