//! Tree variants (`trees.variants`): a species' grown trees are a few variants, each grown
//! once from its own key at the species' nominal height and meshed at LOD1 (the model), every
//! tree a copy of its variant scaled to its height, narrowed, turned and moved, which a GLB
//! draws by instancing and an OBJ holds as copies (docs/trees.md).

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex, OnceLock};

use geo_types::Coord;

use super::mesh::{Frame, Mesh};
use super::tree::{mesh_tree, Lod, Look, Placement, Put};
use crate::templates::species::Species;

/// The variant (from 0) a tree of id `id` is, of `variants` per species; `None` when
/// `variants` is 0 (every tree grown from its own skeleton). Drawn from the tree's own key,
/// so it is the same in any tile, shard or thread, and in `placements.csv`.
pub fn variant_of(seed: u64, id: &str, variants: u32) -> Option<u32> {
    use rand::RngExt;
    (variants > 0)
        .then(|| crate::rng::feature_rng(seed, "tree/variant", id).random_range(0..variants))
}

/// Variant `k` of `species` at its nominal height, roots as the city shows them: grown from
/// its own key (seed, species, k), whatever tree asks for it first.
pub fn grow_variant(
    species: &Species,
    seed: u64,
    k: u32,
) -> Result<crate::growers::skeleton::Skeleton, String> {
    let mut rng = crate::rng::feature_rng(
        seed,
        "tree/variant-growth",
        &format!("{}/{k}", species.name),
    );
    Ok(species
        .grow_in_city(species.nominal_height(), &mut rng)?
        .skeleton)
}

/// Variant `k` of `species` meshed at LOD1 as the tiles show it, at the species' nominal
/// height in `season`, its trunk's foot at the origin (millimetres, x east, y up, z south):
/// the model every tree of the variant is a scaled, turned copy of (and `species/`'s file).
pub fn variant_model(species: &Species, seed: u64, k: u32, season: &str) -> Result<Mesh, String> {
    let sk = grow_variant(species, seed, k)?;
    let mut mesh = Mesh::new(format!("{}_{k}", species.name));
    let place = Placement {
        at: Coord { x: 0.0, y: 0.0 },
        ground: 0.0,
        rotation: 0.0,
    };
    let look = Look::of(species, species.nominal_height(), season);
    let frame = Frame { origin: [0.0, 0.0] };
    mesh_tree(
        &sk,
        &species.mesh,
        look,
        Lod::Reduced,
        place,
        frame,
        &mut mesh,
    );
    Ok(mesh.finish())
}

/// A model of [`Variants`], or why its variant cannot be grown.
type Grown = Result<Arc<Mesh>, String>;

/// Per (species, variant), the cell its model is grown into once.
type Cells = BTreeMap<(String, u32), Arc<OnceLock<Grown>>>;

/// The tree variants of one build, each grown and meshed once ([`variant_model`]) by the
/// first tile that plants a tree of it and shared by every other tile and by `species/`: a
/// variant is the same model in any tile (its key is the build's, not the tile's), and
/// growing it again for each of a city's tiles was a twelfth of an every-feature build.
/// Grown on first use, not up front, so a rebuild of one tile grows only its own variants.
/// Tiles are made on rayon's threads: a thread asking for a variant another is growing
/// waits for it, which is safe because growing never enters rayon itself (a thread waiting
/// in rayon could otherwise pick up a tile that waits on the variant it is growing).
#[derive(Debug)]
pub struct Variants {
    seed: u64,
    season: String,
    /// Per (species, variant), the model once grown.
    grown: Mutex<Cells>,
}

impl Variants {
    /// The variants of a build with the trees' seed `seed` in `season`; none grown yet.
    pub fn new(seed: u64, season: &str) -> Variants {
        Variants {
            seed,
            season: season.to_string(),
            grown: Mutex::new(BTreeMap::new()),
        }
    }

    /// The variants of a build with `params`.
    pub fn of(params: &crate::params::Params) -> Variants {
        Variants::new(params.seed_for("trees"), &params.trees.season)
    }

    /// Variant `k` of `species` at its nominal height ([`variant_model`]), grown on the first
    /// call and shared after it; the same error every time when it cannot be grown.
    pub fn model(&self, species: &Species, k: u32) -> Grown {
        let cell = {
            let mut grown = self.grown.lock().unwrap_or_else(|e| e.into_inner());
            let key = (species.name.clone(), k);
            Arc::clone(grown.entry(key).or_default())
        };
        cell.get_or_init(|| variant_model(species, self.seed, k, &self.season).map(Arc::new))
            .clone()
    }
}

/// How a copy of a model stands: its foot at `place`, `scale` times as tall and
/// `scale * squeeze` times as wide.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stance {
    /// Where and how turned.
    pub place: Placement,
    /// Height over the model's.
    pub scale: f64,
    /// The crown's narrowing (both horizontal axes).
    pub squeeze: f64,
}

/// Adds a copy of `model` (made by [`variant_model`]) standing as `stance` says to `mesh`:
/// each position scaled, turned about the vertical, moved (what a GLB instance's
/// translation, rotation and scale do to the model).
pub fn place_copy(model: &Mesh, stance: Stance, frame: Frame, mesh: &mut Mesh) {
    let put = Put::new(stance.place, frame);
    let (w, h) = (stance.scale * stance.squeeze, stance.scale);
    let pos: Vec<u32> = model
        .positions
        .iter()
        .map(|p| {
            let m = |v: i64| v as f64 / 1000.0;
            put.vertex(mesh, [m(p[0]) * w, -m(p[2]) * w, m(p[1]) * h])
        })
        .collect();
    let uv: Vec<u32> = model
        .uvs
        .iter()
        .map(|t| mesh.uv(f64::from(t[0]) / 10_000.0, f64::from(t[1]) / 10_000.0))
        .collect();
    for f in &model.faces {
        let corners = f
            .corners
            .iter()
            .map(|&(p, t)| (pos[p as usize], uv[t as usize]))
            .collect();
        mesh.face(f.material, corners);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tree_is_one_of_the_variants_by_its_own_key_and_none_without_variants() {
        assert_eq!(variant_of(1, "12/3", 0), None);
        let ks: Vec<u32> = (0..400)
            .map(|i| variant_of(1, &i.to_string(), 8).unwrap())
            .collect();
        assert!(ks.iter().all(|&k| k < 8));
        // Every variant is used, none by more than twice its share.
        for k in 0..8 {
            let n = ks.iter().filter(|&&x| x == k).count();
            assert!((10..=100).contains(&n), "variant {k}: {n} of 400");
        }
        assert_eq!(variant_of(1, "7", 8), variant_of(1, "7", 8));
    }

    /// A variant is grown once and shared: the same model whoever asks, equal to growing it
    /// directly, and a species that cannot grow gives its error each time.
    #[test]
    fn a_variant_is_grown_once_and_is_the_model_grown_directly() {
        let catalog = crate::templates::Catalog::load(None).unwrap();
        let species = catalog.species.values().next().unwrap();
        let variants = Variants::new(5, "summer");
        let first = variants.model(species, 2).unwrap();
        let again = variants.model(species, 2).unwrap();
        assert!(Arc::ptr_eq(&first, &again), "grown once");
        let direct = variant_model(species, 5, 2, "summer").unwrap();
        assert_eq!(first.positions, direct.positions);
        assert_eq!(first.faces.len(), direct.faces.len());
        let other = variants.model(species, 3).unwrap();
        assert!(!Arc::ptr_eq(&first, &other));
        assert_ne!(
            first.positions, other.positions,
            "another variant, another tree"
        );
    }

    #[test]
    fn a_variant_scaled_to_a_height_is_the_variant_grown_at_that_height() {
        // Growing scales the skeleton to its height at the end (roots exposed in
        // proportion), so the shared variant scaled is what each tree would grow.
        let catalog = crate::templates::Catalog::load(None).unwrap();
        for species in catalog.species.values() {
            let h = species.height[0];
            let mut scaled = grow_variant(species, 5, 3).unwrap();
            scaled.scale(h / species.nominal_height());
            let mut rng =
                crate::rng::feature_rng(5, "tree/variant-growth", &format!("{}/3", species.name));
            let direct = species.grow_in_city(h, &mut rng).unwrap().skeleton;
            assert_eq!(scaled.nodes.len(), direct.nodes.len(), "{}", species.name);
            for (a, b) in scaled.nodes.iter().zip(&direct.nodes) {
                for c in 0..3 {
                    assert!((a.at[c] - b.at[c]).abs() < 1e-9, "{}", species.name);
                }
                assert!((a.radius - b.radius).abs() < 1e-9, "{}", species.name);
            }
        }
    }
}
