//! Names derived from an asset's materials: the g-buffer mask channels the bake writes and the
//! presets the import writes, which must agree.

/// The longest name [`channel_name`] gives, in bytes: the longest preset name. OpenEXR refuses
/// channel and attribute names over 255 bytes, file systems file names over 255; 64 keeps
/// `mask.<name>`, the `maskName.<name>` attribute and `<name>.toml` far within both, and
/// readable in a compositor.
pub use crate::material::library::MAX_NAME_BYTES;

/// A name usable in an EXR channel (`mask.<name>`), a look and a preset's file name: letters,
/// digits, '-' and '_' kept, anything else (spaces, dots, slashes) turned into '_'. Dots must
/// go, because `mask.<material>.metallic` uses them to mark the texture masks. A name longer
/// than [`MAX_NAME_BYTES`] keeps its start and ends in `-` and eight hex digits of a hash of the
/// whole label, so it stays unique and the same from one bake to the next.
pub fn channel_name(label: &str) -> String {
    let name: String =
        label.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' }).collect();
    if name.is_empty() {
        return "unnamed".to_string();
    }
    if name.len() <= MAX_NAME_BYTES {
        return name;
    }
    // The name is ASCII, so any byte index is a character boundary.
    format!("{}-{:08x}", &name[..MAX_NAME_BYTES - 9], fnv1a(label.as_bytes()))
}

/// The 32-bit FNV-1a hash: small, stable across versions and platforms.
fn fnv1a(bytes: &[u8]) -> u32 {
    bytes.iter().fold(0x811c_9dc5u32, |hash, &b| (hash ^ b as u32).wrapping_mul(0x0100_0193))
}

/// Makes `name` unique among `taken` by appending `_2`, `_3`, ..., and records it.
pub fn unique(name: String, taken: &mut Vec<String>, same: impl Fn(&str, &str) -> bool) -> String {
    let mut candidate = name.clone();
    let mut n = 2;
    while taken.iter().any(|t| same(t, &candidate)) {
        candidate = format!("{name}_{n}");
        n += 1;
    }
    taken.push(candidate.clone());
    candidate
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_keep_to_safe_characters_and_stay_unique() {
        assert_eq!(channel_name("Rusty Metal.001"), "Rusty_Metal_001");
        assert_eq!(channel_name(""), "unnamed");
        let long = "m".repeat(300);
        let short = channel_name(&long);
        assert_eq!(short.len(), MAX_NAME_BYTES);
        assert!(short.starts_with(&"m".repeat(55)) && short.ends_with(&format!("-{:08x}", fnv1a(long.as_bytes()))));
        assert_ne!(channel_name(&format!("{long}x")), short, "names differing past the cut stay apart");
        let mut taken = Vec::new();
        let exact = |a: &str, b: &str| a == b;
        assert_eq!(unique("paint".into(), &mut taken, exact), "paint");
        assert_eq!(unique("paint".into(), &mut taken, exact), "paint_2");
        assert_eq!(unique("paint".into(), &mut taken, exact), "paint_3");
    }
}
