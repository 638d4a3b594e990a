//! Cryptomatte (Psyop's specification, version 1.2), as Blender, Arnold, Karma and Nuke write
//! it: per pixel, ranks of (id, coverage) pairs, and in the header, for each Cryptomatte layer,
//! `cryptomatte/<key>/name`, `hash` (MurmurHash3_32), `conversion` (uint32_to_float32) and
//! `manifest`, a JSON object from names to the hex of their hashes.
//!
//! A pixel's ids are 32-bit hashes stored as the bits of a float (with the exponent kept off 0
//! and 255, so that no id is a NaN, an infinity or a denormal); rank `NN` of layer `L` is the
//! channels `LNN.r .g .b .a` (or `.R .G .B .A`): two (id, coverage) pairs, ranks in order of
//! coverage.

use std::collections::{BTreeMap, HashMap};

use super::raw::Samples;

/// One Cryptomatte layer declared in a header, with its manifest in file order.
#[derive(Clone, Debug, PartialEq)]
pub struct Declared {
    /// The layer's name, the prefix of its rank channels: `ViewLayer.CryptoObject`.
    pub name: String,
    /// Names and their hashes, in manifest order.
    pub manifest: Vec<(String, u32)>,
}

/// What a layer is about, from its name's ending.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    Object,
    Material,
    Asset,
    /// A layer of another name: its mattes are masks, like materials'.
    Other,
}

impl Declared {
    pub fn role(&self) -> Role {
        let lower = self.name.to_ascii_lowercase().replace('_', "");
        if lower.ends_with("cryptoobject") {
            Role::Object
        } else if lower.ends_with("cryptomaterial") {
            Role::Material
        } else if lower.ends_with("cryptoasset") {
            Role::Asset
        } else {
            Role::Other
        }
    }

    /// The names whose manifest hash is not MurmurHash3_32 of the name, as the specification
    /// requires; their mattes are still read by the manifest's hash.
    pub fn mismatched_hashes(&self) -> Vec<&str> {
        self.manifest
            .iter()
            .filter(|(name, hash)| murmur3_32(name.as_bytes()) != *hash)
            .map(|(n, _)| n.as_str())
            .collect()
    }
}

/// The Cryptomatte layers of a header, in the order of their keys. A layer whose attributes
/// are broken (an unknown hash or conversion, a manifest that is not a JSON object of hex
/// strings, one kept in a sidecar file) is an error naming its key.
pub fn declared(text: &BTreeMap<String, String>) -> Result<Vec<Declared>, String> {
    let mut keys: Vec<&str> =
        text.keys().filter_map(|k| k.strip_prefix("cryptomatte/")?.split_once('/').map(|(key, _)| key)).collect();
    keys.dedup();
    let mut layers = Vec::new();
    for key in keys {
        let get = |field: &str| text.get(&format!("cryptomatte/{key}/{field}"));
        let name = get("name").ok_or_else(|| format!("Cryptomatte layer {key} has no name attribute"))?;
        if let Some(hash) = get("hash").filter(|h| *h != "MurmurHash3_32") {
            return Err(format!("Cryptomatte layer {name} uses the hash {hash}; lookdev reads MurmurHash3_32"));
        }
        if let Some(conversion) = get("conversion").filter(|c| *c != "uint32_to_float32") {
            return Err(format!(
                "Cryptomatte layer {name} uses the conversion {conversion}; lookdev reads uint32_to_float32"
            ));
        }
        let manifest = match (get("manifest"), get("manif_file")) {
            (Some(manifest), _) => parse_manifest(manifest).map_err(|e| format!("Cryptomatte layer {name}: {e}"))?,
            (None, Some(file)) => {
                return Err(format!(
                    "Cryptomatte layer {name} keeps its manifest in the sidecar file {file}; write it into the header"
                ))
            }
            (None, None) => return Err(format!("Cryptomatte layer {name} has no manifest")),
        };
        layers.push(Declared { name: name.clone(), manifest });
    }
    Ok(layers)
}

/// A manifest: a JSON object from names to 8-digit hex hashes, in file order.
fn parse_manifest(text: &str) -> Result<Vec<(String, u32)>, String> {
    let value: serde_json::Value =
        serde_json::from_str(text).map_err(|e| format!("its manifest is not valid JSON ({e})"))?;
    let object = value.as_object().ok_or("its manifest is not a JSON object")?;
    object
        .iter()
        .map(|(name, hash)| {
            let hex = hash.as_str().ok_or_else(|| format!("the manifest's hash of '{name}' is not a string"))?;
            let hash = u32::from_str_radix(hex, 16)
                .map_err(|_| format!("the manifest's hash of '{name}' is not hexadecimal: '{hex}'"))?;
            Ok((name.clone(), hash))
        })
        .collect()
}

/// The rank channel quadruples of a layer, in rank order: `L00.r .g .b .a`, `L01...`, with
/// upper- or lower-case component names.
pub fn ranks<'a>(channels: &'a BTreeMap<String, &'a Samples>, layer: &str) -> Vec<[&'a Samples; 4]> {
    let mut out = Vec::new();
    for rank in 0..100 {
        let quad = ["rgba", "RGBA"].iter().find_map(|components| {
            let mut found = components.chars().map(|c| channels.get(&format!("{layer}{rank:02}.{c}")).copied());
            Some([found.next()??, found.next()??, found.next()??, found.next()??])
        });
        match quad {
            Some(quad) => out.push(quad),
            None => break,
        }
    }
    out
}

/// The coverage of the manifest entries that cover some pixel, from every rank's (id, coverage)
/// pairs. Memory follows the pairs the pixels hold, not the manifest's length: a manifest may
/// name far more entries than the image shows.
pub struct Decoded {
    /// Each entry that covers a pixel, in manifest order: its index in the manifest, and its
    /// (pixel, coverage) pairs in pixel order, one per pixel.
    pub mattes: Vec<(usize, Vec<(u32, f32)>)>,
}

impl Decoded {
    /// An entry's coverage of every pixel.
    pub fn dense(pairs: &[(u32, f32)], pixels: usize) -> Vec<f32> {
        let mut matte = vec![0.0f32; pixels];
        for &(p, coverage) in pairs {
            matte[p as usize] = coverage;
        }
        matte
    }
}

/// Decodes a layer's ranks into the coverage of each manifest entry. Ids that are in no
/// manifest (the background) are left out.
pub fn decode(declared: &Declared, ranks: &[[&Samples; 4]], pixels: usize) -> Decoded {
    let index: HashMap<u32, usize> =
        declared.manifest.iter().enumerate().map(|(i, (_, hash))| (hash_to_float(*hash).to_bits(), i)).collect();
    let mut found: HashMap<usize, Vec<(u32, f32)>> = HashMap::new();
    for quad in ranks {
        let [r, g, b, a] = quad.map(|s| s.as_f32());
        for (ids, coverages) in [(&r, &g), (&b, &a)] {
            for p in 0..pixels.min(ids.len()).min(coverages.len()) {
                if let Some(&entry) = index.get(&ids[p].to_bits()) {
                    let coverage = coverages[p];
                    if coverage.is_finite() && coverage > 0.0 {
                        found.entry(entry).or_default().push((p as u32, coverage));
                    }
                }
            }
        }
    }
    let mut mattes: Vec<(usize, Vec<(u32, f32)>)> = found.into_iter().collect();
    mattes.sort_unstable_by_key(|(entry, _)| *entry);
    for (_, pairs) in &mut mattes {
        // An entry twice in one pixel (in two ranks) covers it by the sum, added in rank order
        // (the sort is stable).
        pairs.sort_by_key(|&(p, _)| p);
        pairs.dedup_by(|later, kept| {
            let same = later.0 == kept.0;
            if same {
                kept.1 += later.1;
            }
            same
        });
    }
    Decoded { mattes }
}

/// MurmurHash3's 32-bit variant (x86_32), seed 0, which Cryptomatte hashes names with.
pub fn murmur3_32(bytes: &[u8]) -> u32 {
    const C1: u32 = 0xcc9e_2d51;
    const C2: u32 = 0x1b87_3593;
    let mix = |k: u32| k.wrapping_mul(C1).rotate_left(15).wrapping_mul(C2);
    let mut h = 0u32;
    let mut blocks = bytes.chunks_exact(4);
    for block in &mut blocks {
        h ^= mix(u32::from_le_bytes(block.try_into().expect("4 bytes")));
        h = h.rotate_left(13).wrapping_mul(5).wrapping_add(0xe654_6b64);
    }
    let tail = blocks.remainder();
    if !tail.is_empty() {
        let k = tail.iter().rev().fold(0u32, |k, &b| (k << 8) | b as u32);
        h ^= mix(k);
    }
    h ^= bytes.len() as u32;
    h ^= h >> 16;
    h = h.wrapping_mul(0x85eb_ca6b);
    h ^= h >> 13;
    h = h.wrapping_mul(0xc2b2_ae35);
    h ^ (h >> 16)
}

/// The float a hash is stored as: its bits, with the exponent clamped into 1..=254.
pub fn hash_to_float(hash: u32) -> f32 {
    let exponent = ((hash >> 23) & 0xff).clamp(1, 254);
    f32::from_bits((hash & 0x807f_ffff) | (exponent << 23))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_hash_as_blender_writes_them() {
        // The manifest Blender 3.4 wrote for a scene with these objects and materials.
        for (name, hash) in
            [("Sphere", 0xe5e9_b0db), ("Sphere.001", 0x8c6d_17c5), ("Cube", 0xa8fc_e865), ("Red Paint", 0x9381_a19c)]
        {
            assert_eq!(murmur3_32(name.as_bytes()), hash, "{name}");
        }
        // The key of a layer is the first 7 hex digits of its name's hash.
        assert_eq!(format!("{:08x}", murmur3_32(b"ViewLayer.CryptoObject"))[..7], *"542cafa");
        assert_eq!(murmur3_32(b""), 0);
        assert_eq!(murmur3_32(b"abc"), 0xb3dd_93fa, "the 3-byte tail");
    }

    #[test]
    fn stored_ids_are_never_nan_infinite_or_denormal() {
        for hash in [0u32, 0x7f80_0000, 0xffff_ffff, 0x0000_0001, 0x7fff_ffff] {
            let id = hash_to_float(hash);
            assert!(id.is_finite() && id.is_normal(), "{hash:08x} gives {id}");
        }
        assert_eq!(hash_to_float(0xe5e9_b0db).to_bits(), 0xe5e9_b0db, "a hash with a usable exponent is kept");
    }

    #[test]
    fn layers_and_mattes_decode_from_ranks() {
        let mut text = BTreeMap::new();
        text.insert("cryptomatte/542cafa/name".to_string(), "L.CryptoObject".to_string());
        text.insert("cryptomatte/542cafa/hash".to_string(), "MurmurHash3_32".to_string());
        text.insert("cryptomatte/542cafa/conversion".to_string(), "uint32_to_float32".to_string());
        text.insert("cryptomatte/542cafa/manifest".to_string(), r#"{"Sphere":"e5e9b0db","Cube":"a8fce865"}"#.into());
        let layers = declared(&text).unwrap();
        assert_eq!(layers.len(), 1);
        assert_eq!(layers[0].role(), Role::Object);
        assert_eq!(layers[0].manifest[0], ("Sphere".to_string(), 0xe5e9_b0db), "manifest order is kept");
        assert!(layers[0].mismatched_hashes().is_empty());

        let (sphere, cube) = (hash_to_float(0xe5e9_b0db), hash_to_float(0xa8fc_e865));
        // Two pixels: all sphere; 0.6 cube and 0.3 sphere over 0.1 background.
        let r = Samples::F32(vec![sphere, cube]);
        let g = Samples::F32(vec![1.0, 0.6]);
        let b = Samples::F32(vec![0.0, sphere]);
        let a = Samples::F32(vec![0.0, 0.3]);
        let mut channels = BTreeMap::new();
        for (c, s) in [("r", &r), ("g", &g), ("b", &b), ("a", &a)] {
            channels.insert(format!("L.CryptoObject00.{c}"), s);
        }
        let ranks = ranks(&channels, "L.CryptoObject");
        assert_eq!(ranks.len(), 1);
        let decoded = decode(&layers[0], &ranks, 2);
        assert_eq!(decoded.mattes, vec![(0, vec![(0, 1.0), (1, 0.3)]), (1, vec![(1, 0.6)])]);
        assert_eq!(Decoded::dense(&decoded.mattes[1].1, 2), vec![0.0, 0.6]);

        text.insert("cryptomatte/542cafa/manifest".to_string(), r#"{"Sphere":"e5e9b0dz"}"#.into());
        assert!(declared(&text).unwrap_err().contains("not hexadecimal: 'e5e9b0dz'"));
        text.insert("cryptomatte/542cafa/manifest".to_string(), "[1, 2]".into());
        assert!(declared(&text).unwrap_err().contains("L.CryptoObject: its manifest is not a JSON object"));
    }
}
