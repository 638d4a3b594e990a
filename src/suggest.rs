//! Messages for names that are not known: the names that are, and the closest one when it is
//! near enough to be a typo. Every reader and flag words them the same way.

/// The message for a key that is not one of `expected`: lists them, and suggests the closest
/// when it is near enough to be a typo.
/// `place` ("in [render]") may be empty.
pub fn unknown(noun: &str, key: &str, place: &str, expected: &[&str]) -> String {
    let place = if place.is_empty() { String::new() } else { format!(" {place}") };
    let mut message = format!("unknown {noun} '{key}'{place} (expected {})", expected.join(", "));
    if let Some(near) = near_miss(key, expected) {
        message.push_str(&format!("; did you mean '{near}'?"));
    }
    message
}

/// The candidate closest to `name`, if it is within two edits or a third of its length.
pub fn near_miss<'a>(name: &str, candidates: &[&'a str]) -> Option<&'a str> {
    let limit = (name.chars().count() / 3).max(2);
    closest(name, candidates.iter().copied()).into_iter().next().filter(|c| edit_distance(name, c) <= limit)
}

/// All candidates, closest to `name` first (ties in alphabetical order).
pub fn closest<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> Vec<&'a str> {
    let mut ranked: Vec<(usize, &str)> = candidates.into_iter().map(|c| (edit_distance(name, c), c)).collect();
    ranked.sort();
    ranked.dedup();
    ranked.into_iter().map(|(_, c)| c).collect()
}

/// Edit distance: the fewest single-character insertions, deletions, substitutions and swaps of
/// two neighbours (optimal string alignment), so that the common typo "maks" is one edit from
/// "mask".
pub fn edit_distance(a: &str, b: &str) -> usize {
    let (a, b): (Vec<char>, Vec<char>) = (a.chars().collect(), b.chars().collect());
    // A name this long is no typo of a short one; the table would be as large as the product.
    const LONGEST: usize = 128;
    if a.len() > LONGEST || b.len() > LONGEST {
        return a.len().max(b.len());
    }
    // d[i][j] is the distance between the first i characters of a and the first j of b.
    let mut d = vec![vec![0usize; b.len() + 1]; a.len() + 1];
    for (i, row) in d.iter_mut().enumerate() {
        row[0] = i;
    }
    d[0] = (0..=b.len()).collect();
    for i in 1..=a.len() {
        for j in 1..=b.len() {
            let substitute = d[i - 1][j - 1] + usize::from(a[i - 1] != b[j - 1]);
            let mut best = substitute.min(d[i - 1][j] + 1).min(d[i][j - 1] + 1);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                best = best.min(d[i - 2][j - 2] + 1);
            }
            d[i][j] = best;
        }
    }
    d[a.len()][b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edit_distances() {
        assert_eq!(edit_distance("", ""), 0);
        assert_eq!(edit_distance("gold", "gold"), 0);
        assert_eq!(edit_distance("golld", "gold"), 1);
        assert_eq!(edit_distance("sppp", "spp"), 1);
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("maks", "mask"), 1, "a swap of neighbours is one edit");
        assert_eq!(edit_distance("maks", "map"), 2);
    }

    #[test]
    fn near_misses_only_when_near() {
        assert_eq!(near_miss("rougness", &["roughness", "metallic"]), Some("roughness"));
        assert_eq!(near_miss("sppp", &["spp", "seed"]), Some("spp"));
        assert_eq!(near_miss("banana", &["spp", "seed"]), None);
    }
}
