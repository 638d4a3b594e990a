//! Names derived from an asset's materials: the g-buffer mask channels the bake writes and the
//! presets the import writes, which must agree.

/// A name usable in an EXR channel (`mask.<name>`) and a look: letters, digits, '-' and '_'
/// kept, anything else (spaces, dots, slashes) turned into '_'. Dots must go, because
/// `mask.<material>.metallic` uses them to mark the texture masks.
pub fn channel_name(label: &str) -> String {
    let name: String =
        label.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' }).collect();
    if name.is_empty() {
        "unnamed".to_string()
    } else {
        name
    }
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
        let mut taken = Vec::new();
        let exact = |a: &str, b: &str| a == b;
        assert_eq!(unique("paint".into(), &mut taken, exact), "paint");
        assert_eq!(unique("paint".into(), &mut taken, exact), "paint_2");
        assert_eq!(unique("paint".into(), &mut taken, exact), "paint_3");
    }
}
