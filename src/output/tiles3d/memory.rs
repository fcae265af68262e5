//! The parents of the build before, kept between the workbench's rebuilds (issue 61): a
//! parent whose leaves, their frames and shared models, the textures and the settings are
//! what they were is taken as it was made (its node, its shed content, its subtree's files)
//! instead of reading its leaves back and coarsening them again. One lot edited remakes the
//! parents on its leaf's way to the root and no others.
//!
//! A parent's key hashes everything its file and node are made from: its level and cell,
//! the build-wide part ([`Keys::base`]: program version, textures, compression, tile size),
//! and its children's keys down to the leaves' (a leaf's GLB and shared models by sha256,
//! its frame and box). Equal keys make equal bytes: the property test
//! `tests/workbench_reuse.rs` compares every rebuild with a full build, file for file.
//!
//! The memory is taken out when a tileset starts and put back whole when it is written, so a
//! build that fails among the parents leaves none remembered (the files on disk may then be
//! anybody's), and a remembered parent is used only while its file is on disk at its size.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use serde_json::Value;
use sha2::{Digest, Sha256};

use super::{lod, Aabb, Group, Leaf, Made};
use crate::output::report::{Manifest, ManifestFile};

/// The parents a tileset made or kept, by name (`<level>_<x>_<y>`), for the next build into
/// the same directory. Empty until a tileset is written with it.
#[derive(Debug, Default)]
pub struct Memory {
    parents: Mutex<BTreeMap<String, Remembered>>,
    /// How many parents the last tileset kept rather than made.
    kept: AtomicUsize,
    /// The textures' mean colours, by the bytes they were measured from.
    colours: Mutex<lod::colours::KnownColours>,
}

impl Memory {
    /// How many parents the last tileset written with it kept as they were.
    pub fn kept(&self) -> usize {
        self.kept.load(Ordering::Relaxed)
    }

    /// Everything remembered, leaving the memory empty.
    pub(super) fn take(&self) -> BTreeMap<String, Remembered> {
        std::mem::take(&mut *self.lock())
    }

    /// Remembers `parents` in place of whatever it held, `kept` of them as they were.
    pub(super) fn put(&self, parents: BTreeMap<String, Remembered>, kept: usize) {
        *self.lock() = parents;
        self.kept.store(kept, Ordering::Relaxed);
    }

    /// The textures' colours measured by the tilesets before (read and replaced by the
    /// next).
    pub(super) fn colours(&self) -> &Mutex<lod::colours::KnownColours> {
        &self.colours
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, BTreeMap<String, Remembered>> {
        // A panic elsewhere never leaves the map half-changed: it is swapped whole.
        self.parents.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// One parent as it was made.
#[derive(Debug, Clone)]
pub(super) struct Remembered {
    /// What it was made from.
    pub key: [u8; 32],
    /// Its box in the root's frame.
    pub bounds: Aabb,
    /// Its node in `tileset.json`, children and all.
    pub json: Value,
    /// Its content, shed for its own parent.
    pub content: lod::Content,
    /// The parents' files of its subtree, itself included.
    pub made: Vec<Made>,
}

impl Remembered {
    /// Whether its subtree's files are on disk at their sizes (the directory is locked and
    /// was written by the tileset that remembered them).
    pub fn on_disk(&self, out: &Path) -> bool {
        (self.made.iter()).all(|(_, _, f)| crate::output::listed::at_size(out, f))
    }
}

/// Every node's key, level by level (`keys[0]` the leaves').
pub(super) struct Keys(Vec<Vec<[u8; 32]>>);

impl Keys {
    /// The keys of the tree over `leaves` grouped as `groups` ([`super::hierarchy`]).
    pub fn of(manifest: &Manifest, leaves: &[Leaf], groups: &[Vec<Group>], meshopt: bool) -> Keys {
        let leaves = leaves.iter().map(leaf_key).collect();
        Self::above(Self::base(manifest, meshopt), leaves, groups)
    }

    /// The keys of the parents over leaves of keys `leaves`, each hashing `base`.
    fn above(base: [u8; 32], leaves: Vec<[u8; 32]>, groups: &[Vec<Group>]) -> Keys {
        let mut levels = vec![leaves];
        for (l, level) in groups.iter().enumerate() {
            let below = &levels[l];
            let keys = level
                .iter()
                .map(|(cell, children)| {
                    let mut h = Sha256::new();
                    h.update(base);
                    h.update((l as u64 + 1).to_le_bytes());
                    h.update(cell.0.to_le_bytes());
                    h.update(cell.1.to_le_bytes());
                    for &c in children {
                        h.update(below[c]);
                    }
                    h.finalize().into()
                })
                .collect();
            levels.push(keys);
        }
        Keys(levels)
    }

    /// The key of node `index` of `level`.
    pub fn get(&self, level: usize, index: usize) -> [u8; 32] {
        self.0[level][index]
    }

    /// What every parent is made with besides its leaves: this program, the textures whose
    /// mean colours replace them, the compression and the tile size (each level's target).
    fn base(manifest: &Manifest, meshopt: bool) -> [u8; 32] {
        let mut h = Sha256::new();
        h.update(env!("CARGO_PKG_VERSION").as_bytes());
        h.update([meshopt as u8]);
        h.update(manifest.tile_size.to_le_bytes());
        for t in &manifest.textures {
            file(&mut h, t);
        }
        h.finalize().into()
    }
}

/// A leaf's GLB and the shared models it draws, its frame and its box.
fn leaf_key(l: &Leaf) -> [u8; 32] {
    let mut h = Sha256::new();
    h.update(l.cell.0.to_le_bytes());
    h.update(l.cell.1.to_le_bytes());
    for f in l.tile.glb.iter().chain(&l.tile.models) {
        file(&mut h, f);
    }
    for v in l.transform.column_major() {
        h.update(v.to_le_bytes());
    }
    for v in l.local.lo.iter().chain(&l.local.hi) {
        h.update(v.to_le_bytes());
    }
    h.finalize().into()
}

fn file(h: &mut Sha256, f: &ManifestFile) {
    h.update(f.path.as_bytes());
    h.update([0]);
    h.update(f.sha256.as_bytes());
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A leaf's change changes the keys of its parents up to the root, and no other: what
    /// lets an edit remake one path of the tree.
    #[test]
    fn a_leaf_changes_its_ancestors_keys_only() {
        // Eight leaves in two groups of four, under one root.
        let cells: Vec<(i64, i64)> = (0..8).map(|i| (i % 4, i / 4 * 4)).collect();
        let groups = crate::output::tiles3d::hierarchy(&cells);
        assert_eq!(groups.len(), 2, "{groups:?}");
        let leaves: Vec<[u8; 32]> = (0..8u8).map(|i| [i; 32]).collect();
        let before = Keys::above([0; 32], leaves.clone(), &groups);
        let mut edited = leaves;
        edited[5] = [99; 32];
        let after = Keys::above([0; 32], edited, &groups);
        let holder = groups[0].iter().position(|(_, c)| c.contains(&5)).unwrap();
        for (g, _) in groups[0].iter().enumerate() {
            let same = before.get(1, g) == after.get(1, g);
            assert_eq!(same, g != holder, "group {g} of level 1");
        }
        assert_ne!(before.get(2, 0), after.get(2, 0), "the root");
        // The build-wide part is in every parent's key.
        let other = Keys::above([1; 32], (0..8u8).map(|i| [i; 32]).collect(), &groups);
        assert!((0..groups[0].len()).all(|g| other.get(1, g) != before.get(1, g)));
    }
}
