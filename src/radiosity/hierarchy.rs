//! Hierarchical radiosity (Hanrahan, Salzman and Aupperle 1991). Every
//! patch (a diffuse scene triangle) is the root of a tree of elements, four
//! children per node by midpoint subdivision (the numbering of
//! [`super::Mesh`]). Two nodes exchange light through a link when the
//! light it carries, bounded by ρ_p B_q F_max A_p with F the unoccluded
//! form factor at p's corners and centroid, is below ε times the emitted
//! power (Hanrahan's "BF" oracle) or both are as small as allowed; otherwise the larger
//! one is subdivided and its children are linked instead; a link through a
//! shadow boundary is refined further, down to [`PARTIAL_SHARE`] of ε. A solve step
//! gathers over every link (Jacobi), then pushes what a node gathered down
//! to its leaves and pulls area-weighted radiance up ("push-pull"), then
//! refines the links the new radiance makes too coarse. The cost is linear
//! in the number of links instead of quadratic in the elements. Parts of
//! patches no light leaves (the floor under a block, the ceiling behind the
//! light) are measured per node ([`exposure`]): a node sends its reflected
//! light from its open part only, and keeps links that found it dark, since
//! its open part may see through them.

use super::VertexField;
use super::cluster::ClusterKind;
use super::element::Element;
use super::form_factor::{
    EXPOSURE_POINTS, Exchange, FormFactorMethod, exposure, point_to_polygon,
    probed_element_to_element, sent_radiance,
};
use super::mesh::{back_of, exposed_backs};
use crate::accel::Geometry;
use crate::math::Rgb;
use crate::scene::Scene;
use rayon::prelude::*;

mod clusters;
mod queries;
mod refine;
mod smooth;

use clusters::{Clusters, is_cluster};

/// A link: the node gathers from `source` (a node, or a cluster: see
/// [`clusters`]) with form factor `f`, of which the share `visibility` of
/// its shadow rays arrived; `f_max` is the oracle's unoccluded bound
/// (geometry only, so kept rather than recomputed at every step).
#[derive(Clone, Copy, Debug)]
struct Link {
    source: u32,
    f: f32,
    visibility: f32,
    f_max: f32,
}

/// One element of a patch's tree.
#[derive(Clone, Debug)]
struct Node {
    element: Element,
    depth: u8,
    /// First of four consecutive children, or `NONE`.
    children: u32,
    /// Light gathered over this node's own links (before reflection).
    gathered: Rgb,
    /// Radiance: emission plus reflected (leaves), area mean (inner nodes).
    radiance: Rgb,
    /// The share of the node light can leave from ([`exposure`]); NaN until
    /// measured.
    exposure: f32,
    links: Vec<Link>,
}

const NONE: u32 = u32::MAX;
/// Deepest level of a patch's tree.
const MAX_DEPTH: u8 = 10;

/// Settings of the hierarchical solver.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HierarchySettings {
    /// The BF oracle's threshold, relative to the emitted power.
    pub epsilon: f32,
    /// Smallest element edge, as a fraction of the scene's diagonal.
    pub min_size: f32,
    pub method: FormFactorMethod,
    pub samples: u32,
    /// Most nodes (each about 100 bytes plus its links).
    pub max_nodes: usize,
    /// How clusters above the patches estimate their projected area.
    pub clusters: ClusterKind,
}

/// The trees, their links and the solution.
pub struct Hierarchy {
    nodes: Vec<Node>,
    /// Per scene triangle, its root node (`NONE` if not a patch), and that
    /// of its back ([`exposed_backs`]; empty if no triangle has one).
    roots: Vec<u32>,
    back_roots: Vec<u32>,
    /// Per scene triangle, whether its back is a patch of its own.
    two_sided: Vec<bool>,
    /// The clusters above the patches, their links and radiance.
    clusters: Clusters,
    min_area: f32,
    emitted: f64,
    settings: HierarchySettings,
    /// Shadow rays cast for form factors so far.
    pub rays: u64,
    pub steps: u64,
    /// What is not a patch, and whether refinement hit the node budget.
    pub notes: Vec<String>,
    budget_spent: bool,
    /// Smooth display: per node, its vertices' radiance (leaves only; set
    /// by [`Hierarchy::smooth`]).
    vertex_radiance: VertexField,
    /// Per node, the radiance ([`Hierarchy::exitant`]) the last step
    /// gathered from (children made since take their parent's), so that the
    /// smooth display's gather shows the same bounce as the leaves: one step
    /// is direct light.
    gathered_from: Vec<Rgb>,
}

/// A link through a shadow boundary is refined while its transfer exceeds
/// this share of ε: constant elements smear the boundary over their size,
/// and an element half hidden (the ceiling behind the light) shows its
/// hidden half's darkness on its visible half. Cornell box, smooth display,
/// masked RMSE at about equal solve time, 1/16 against 1/8: 0.00218 against
/// 0.00208 at 0.13 s, 0.00159 against 0.00149 at 0.39 s, even from 0.9 s
/// on (0.00114 at 0.90 s; 0.00128 at 0.65 s and 0.00103 at 1.18 s); 1/4
/// gave 0.00227 at 0.12 s.
const PARTIAL_SHARE: f32 = 1.0 / 8.0;

/// A coarse link splits its source only where the source is more than this
/// many times the gatherer's area, else the gatherer: the gatherer's leaves
/// are what the display shows, and between elements of nearly equal area
/// (a wall's triangle and the next wall's, one level apart in area by a
/// factor of 4) splitting the source sharpens nothing on screen.
/// Hanrahan's rule, the larger of the two (a ratio of 1), gave on the
/// Cornell box a masked RMSE 8-10% higher at equal time: 0.00167 against
/// 0.00159 in 0.38-0.40 s, 0.00127 against 0.00114 in 0.90 s (both at
/// [`PARTIAL_SHARE`] 1/16). A ratio of 4 (the source one level coarser)
/// was worse where elements are large: 0.00252 against 0.00208 at ε 1e-4.
const SOURCE_SPLIT_RATIO: f32 = 2.0;

/// Samples of a new link's exchange that may decide its split on their own.
const PROBE_SAMPLES: u32 = 4;

/// Shadow rays per partly visible link at a vertex of the smooth display.
const VERTEX_RAYS: u32 = 4;

fn partly_visible(visibility: f32) -> bool {
    visibility > 0.0 && visibility < 1.0
}

fn luminance(c: Rgb) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

impl Hierarchy {
    /// Roots for every diffuse triangle and the initial links between them;
    /// triangles marked in `hidden` (empty: none) have no front root (see
    /// [`super::Mesh::build`]).
    pub fn build(
        scene: &Scene,
        settings: HierarchySettings,
        hidden: &[bool],
    ) -> Result<Hierarchy, String> {
        if !(settings.epsilon > 0.0 && settings.epsilon.is_finite()) {
            return Err(format!(
                "epsilon {} is not a positive number",
                settings.epsilon
            ));
        }
        if !(settings.min_size > 0.0 && settings.min_size.is_finite()) {
            return Err(format!(
                "patch size {} is not a positive fraction",
                settings.min_size
            ));
        }
        let geometry = &scene.geometry;
        // Every triangle may be a patch on both sides; refused before any
        // allocation grows with them.
        let most = 2 * geometry.triangles().len();
        let per_patch = std::mem::size_of::<Node>() + clusters::BYTES_PER_PATCH;
        if most > settings.max_nodes {
            return Err(format!(
                "{} triangles may need {} patches (about {} MiB before refinement), more than \
                 the budget of {} elements",
                geometry.triangles().len(),
                most,
                (most * per_patch) >> 20,
                settings.max_nodes
            ));
        }
        let bounds = geometry.bounds();
        let diagonal = (bounds.max - bounds.min).length();
        let mut nodes = Vec::new();
        let mut roots = Vec::with_capacity(geometry.triangles().len());
        let mut specular = 0;
        for (i, v) in geometry.triangles().iter().enumerate() {
            let Some((reflectance, _)) = scene.diffuse_albedo(geometry.triangle_material(i)) else {
                specular += 1;
                roots.push(NONE);
                continue;
            };
            let emission = scene.triangle_emission(i);
            let element = Element::new(i as u32, *v, reflectance, emission);
            if !(element.area > 0.0) || hidden.get(i).copied().unwrap_or(false) {
                roots.push(NONE);
                continue;
            }
            roots.push(nodes.len() as u32);
            nodes.push(Node {
                element,
                depth: 0,
                children: NONE,
                gathered: Rgb::ZERO,
                radiance: emission,
                exposure: f32::NAN,
                links: Vec::new(),
            });
        }
        let two_sided = exposed_backs(scene);
        let mut back_roots = Vec::new();
        if two_sided.contains(&true) {
            back_roots = vec![NONE; roots.len()];
            for (i, v) in geometry.triangles().iter().enumerate() {
                // A hidden front's back may still be open (a table's
                // underside below what stands on it).
                let material = geometry.triangle_material(i);
                let albedo = scene.diffuse_albedo(material);
                let (true, Some((reflectance, _))) = (two_sided[i], albedo) else {
                    continue;
                };
                let front = Element::new(i as u32, *v, reflectance, Rgb::ZERO);
                if !(front.area > 0.0) {
                    continue;
                }
                back_roots[i] = nodes.len() as u32;
                nodes.push(Node {
                    element: back_of(&front, roots.len()),
                    depth: 0,
                    children: NONE,
                    gathered: Rgb::ZERO,
                    radiance: Rgb::ZERO,
                    exposure: f32::NAN,
                    links: Vec::new(),
                });
            }
        }
        if nodes.is_empty() {
            return Err("radiosity needs diffuse surfaces: the scene has none".into());
        }
        let emitted: f64 = nodes
            .iter()
            .map(|n| n.element.area as f64 * luminance(n.element.emission) as f64)
            .sum();
        if emitted <= 0.0 {
            return Err(
                "radiosity needs an emissive diffuse surface: the scene has none \
                        (point lights and spheres are not patches)"
                    .into(),
            );
        }
        let min_size = settings.min_size * diagonal;
        let clusters = Clusters::build(&nodes, settings.clusters);
        let mut h = Hierarchy {
            nodes,
            roots,
            back_roots,
            two_sided,
            clusters,
            // The area of an equilateral triangle of edge min_size.
            min_area: 0.433 * min_size * min_size,
            emitted,
            settings,
            rays: 0,
            steps: 0,
            notes: Vec::new(),
            budget_spent: false,
            vertex_radiance: VertexField::default(),
            gathered_from: Vec::new(),
        };
        let backs = h.back_roots.iter().filter(|&&r| r != NONE).count();
        if backs > 0 {
            h.notes.push(format!(
                "{backs} thin triangles lit from behind are patches on both sides"
            ));
        }
        if specular > 0 {
            h.notes.push(format!(
                "{specular} mirror, conductor and glass triangles are not patches: they block light between \
                 patches, and camera rays are traced through them (caustics are missing)"
            ));
        }
        h.notes.extend(super::mesh::light_notes(scene));
        // One self-link of the whole scene, refined by the oracle.
        h.measure_exposure(geometry);
        // The clusters' radiance (the lights) for the oracle's first round.
        let sent: Vec<Rgb> = (0..h.nodes.len() as u32).map(|k| h.exitant(k)).collect();
        h.pull_clusters(&sent);
        if let Some(root) = h.clusters.root() {
            h.link_all(geometry, vec![(root, root, false)]);
        }
        Ok(h)
    }

    /// The radiance node k sends: its reflected light spread over the part
    /// light can leave from. A node's radiance is the mean over all of it,
    /// hidden part included (no light reaches under a block), but what it
    /// sends leaves from its exposed part alone; sent at the mean, the floor
    /// around a block lit the block's base too little (its dark band, 28% of
    /// the squared error at ε 1e-4).
    fn exitant(&self, k: u32) -> Rgb {
        if is_cluster(k) {
            return self.cluster_sent(k);
        }
        let node = &self.nodes[k as usize];
        // Nodes made by this round's refinement are measured before the next.
        let exposure = if node.exposure.is_nan() {
            1.0
        } else {
            node.exposure
        };
        sent_radiance(node.radiance, node.element.emission, exposure)
    }

    /// The radiance node or cluster k sent in the last step's gather (what
    /// it sends now, if made since).
    fn sent_by(&self, k: u32) -> Rgb {
        if is_cluster(k) {
            return self.cluster_sent(k);
        }
        let from = self.gathered_from.get(k as usize);
        from.copied().unwrap_or_else(|| self.exitant(k))
    }

    /// Measures the exposure of nodes made since the last call, in parallel.
    fn measure_exposure(&mut self, geometry: &Geometry) {
        let new: Vec<u32> = (0..self.nodes.len() as u32)
            .into_par_iter()
            .filter(|&k| self.nodes[k as usize].exposure.is_nan())
            .collect();
        let nodes = &self.nodes;
        let measured: Vec<(f32, u32)> = new
            .par_iter()
            .map(|&k| {
                exposure(
                    geometry,
                    &self.two_sided,
                    &nodes[k as usize].element,
                    EXPOSURE_POINTS,
                )
            })
            .collect();
        for (&k, (share, rays)) in new.iter().zip(measured) {
            self.nodes[k as usize].exposure = share;
            self.rays += u64::from(rays);
        }
    }

    /// Leaves and links, for reports.
    pub fn counts(&self) -> (usize, usize) {
        let leaves = self.nodes.iter().filter(|n| n.children == NONE).count();
        let links = self.nodes.iter().map(|n| n.links.len()).sum::<usize>();
        (leaves, links + self.clusters.link_count())
    }

    /// Bytes the nodes and links take.
    pub fn memory_bytes(&self) -> usize {
        let links: usize = self.nodes.iter().map(|n| n.links.len()).sum();
        self.nodes.len() * std::mem::size_of::<Node>()
            + links * std::mem::size_of::<Link>()
            + self.clusters.memory_bytes()
            + self.gathered_from.len() * std::mem::size_of::<Rgb>()
            + self.vertex_radiance.memory_bytes()
    }

    /// The oracle: a bound on the light a link from q to p carries, and so
    /// on how far it may be off at some point of p, relative to the emitted
    /// power: ρ_p B_q F_max A_p, with F_max the largest unoccluded
    /// point-to-polygon form factor at p's centroid and corners (pulled 5%
    /// towards the centroid). It bounds both the transfer (Hanrahan's BF)
    /// and its variation over p (F_max - F_min); either alone left single
    /// leaves of a uniform closed box further from E/(1 - ρ) (1.4% and 3.8%).
    fn f_max(&self, p: u32, q: u32) -> f32 {
        let e = &self.nodes[p as usize].element;
        let source = &self.nodes[q as usize].element;
        let centroid = (e.vertices[0] + e.vertices[1] + e.vertices[2]) / 3.0;
        let mut high = 0.0f32;
        for x in [centroid, e.vertices[0], e.vertices[1], e.vertices[2]] {
            let x = x + 0.05 * (centroid - x);
            high = high.max(point_to_polygon(x, e.normal, &source.vertices));
        }
        high
    }

    /// The oracle's bound for a link from q to p with bound `f_max`,
    /// relative to the emitted power.
    fn transfer(&self, p: u32, q: u32, f_max: f32) -> f32 {
        let e = &self.nodes[p as usize].element;
        let light = luminance(e.reflectance * self.oracle_radiance(q));
        (light as f64 * f_max as f64 * e.area as f64 / self.emitted) as f32
    }

    /// Whether node `k` may be subdivided.
    fn divisible(&self, k: u32) -> bool {
        if is_cluster(k) {
            return true;
        }
        let n = &self.nodes[k as usize];
        n.depth < MAX_DEPTH && n.element.area > 4.0 * self.min_area
    }

    /// Creates node k's four children if it has none; None once the node
    /// budget is spent (refinement then stops where it is, and says so).
    fn subdivide(&mut self, k: u32) -> Option<u32> {
        if self.nodes[k as usize].children != NONE {
            return Some(self.nodes[k as usize].children);
        }
        if self.nodes.len() + 4 > self.settings.max_nodes {
            if !self.budget_spent {
                self.budget_spent = true;
                self.notes.push(format!(
                    "refinement stopped at {} elements (the budget): epsilon {} and patch size {} \
                     ask for more; the solution is coarser than they would give",
                    self.nodes.len(),
                    self.settings.epsilon,
                    self.settings.min_size
                ));
            }
            return None;
        }
        let parent = self.nodes[k as usize].clone();
        let first = self.nodes.len() as u32;
        for vertices in super::mesh::children(parent.element.vertices) {
            self.nodes.push(Node {
                element: Element {
                    vertices,
                    area: 0.25 * parent.element.area,
                    ..parent.element
                },
                depth: parent.depth + 1,
                children: NONE,
                gathered: Rgb::ZERO,
                radiance: parent.radiance,
                exposure: f32::NAN,
                links: Vec::new(),
            });
        }
        self.nodes[k as usize].children = first;
        if let Some(&from) = self.gathered_from.get(k as usize) {
            self.gathered_from.extend([from; 4]);
        }
        Some(first)
    }

    /// Links every (gatherer, source, forced) pair: those with a cluster at
    /// one end through the clusters' oracle, which hands the pairs of
    /// elements it reaches to [`Hierarchy::link`].
    fn link_all(&mut self, geometry: &Geometry, pairs: Vec<(u32, u32, bool)>) {
        let (clustered, mut elements): (Vec<_>, Vec<_>) = pairs
            .into_iter()
            .partition(|&(p, q, _)| is_cluster(p) || is_cluster(q));
        self.link_clusters(geometry, clustered, &mut elements);
        self.link(geometry, elements);
    }

    /// Links every (gatherer, source, forced) pair of elements, subdividing while the
    /// oracle finds an exchange too coarse; a forced pair is split once
    /// regardless. The new links' form factors, where the rays go, are
    /// estimated in parallel between rounds of refinement; a partly visible
    /// link whose transfer is above [`PARTIAL_SHARE`] of ε goes back for
    /// another round, split.
    fn link(&mut self, geometry: &Geometry, mut pairs: Vec<(u32, u32, bool)>) {
        let mut pending = Vec::new();
        while !pairs.is_empty() {
            pending.clear();
            self.refine(std::mem::take(&mut pairs), &mut pending);
            self.measure_exposure(geometry);
            let (nodes, settings) = (&self.nodes, self.settings);
            let link_of = |(q, f_max), x: &Exchange| Link {
                source: q,
                f: x.f,
                visibility: x.visibility,
                f_max,
            };
            // A link whose first rays already disagree is split whatever the
            // rest say (17% of the exchanges at ε 7e-5): same links, fewer rays.
            let exchanges: Vec<Exchange> = pending
                .par_iter()
                .map(|&(p, q, f_max)| {
                    probed_element_to_element(
                        geometry,
                        (&nodes[p as usize].element, &nodes[q as usize].element),
                        settings.method,
                        settings.samples,
                        (p, p ^ (q << 16)),
                        PROBE_SAMPLES,
                        |x| self.splits(p, &link_of((q, f_max), x)),
                    )
                })
                .collect();
            for (&(p, q, f_max), x) in pending.iter().zip(exchanges) {
                self.rays += x.rays as u64;
                let link = link_of((q, f_max), &x);
                if self.splits(p, &link) {
                    pairs.push((p, q, true));
                } else if x.f > 0.0
                    || (f_max > 0.0 && self.transfer(p, q, f_max) == 0.0)
                    || self.partly_hidden(p)
                {
                    // Kept although its rays all missed: a partly hidden
                    // gatherer's dark links (its open part may see through
                    // them: the ceiling by the light), and a link from a
                    // source still dark when linked, which is re-examined
                    // once the source is lit. Dropped, the indirect room's
                    // ceiling beside the lamp shade lost for good a wall it
                    // sees through the opening (15% of its light there):
                    // masked RMSE 0.00580 -> 0.00284 against the deep
                    // reference; Cornell box ε 3e-5 0.00159 -> 0.00160.
                    self.nodes[p as usize].links.push(link);
                }
            }
        }
    }

    /// Whether a link is to be replaced by finer ones (see `too_coarse`).
    fn splits(&self, p: u32, link: &Link) -> bool {
        let divisible = self.divisible(p) || self.divisible(link.source);
        self.too_coarse(p, link) && divisible && !self.budget_spent
    }

    /// Whether a link is too coarse for the current radiance: its transfer
    /// above ε, or above [`PARTIAL_SHARE`] of ε through a shadow boundary.
    fn too_coarse(&self, p: u32, link: &Link) -> bool {
        let transfer = self.transfer(p, link.source, link.f_max);
        transfer > self.settings.epsilon
            || (transfer > self.settings.epsilon * PARTIAL_SHARE && self.uncertain(p, link))
    }

    /// Whether node p is hidden in part (not all of it, not none).
    fn partly_hidden(&self, p: u32) -> bool {
        let exposure = self.nodes[p as usize].exposure;
        exposure > 0.0 && exposure < 1.0
    }

    /// Whether a link's visibility may differ over its gatherer: some of
    /// its rays arrived and some did not, or none did from a gatherer that
    /// is partly hidden, whose points may all have fallen on the hidden part.
    fn uncertain(&self, p: u32, link: &Link) -> bool {
        partly_visible(link.visibility) || (link.visibility == 0.0 && self.partly_hidden(p))
    }

    /// One step: gather over every link, push-pull, then refine the links
    /// the new radiance makes too coarse. Returns the change in radiance
    /// (area-weighted, over the emitted power).
    pub fn step(&mut self, geometry: &Geometry) -> f64 {
        self.steps += 1;
        self.measure_exposure(geometry);
        let sent: Vec<Rgb> = (0..self.nodes.len() as u32)
            .into_par_iter()
            .map(|k| self.exitant(k))
            .collect();
        self.pull_clusters(&sent);
        self.gathered_from = sent;
        self.refresh_weights();
        let gathered: Vec<Rgb> = self
            .nodes
            .par_iter()
            .map(|n| {
                n.links
                    .iter()
                    .fold(Rgb::ZERO, |acc, l| acc + l.f * self.sent_by(l.source))
            })
            .collect();
        // What the patches' ancestor clusters gathered, by each patch's normal.
        let patches = self.clusters.patch_count() as u32;
        let from_clusters: Vec<Rgb> = (0..patches)
            .into_par_iter()
            .map(|k| {
                let e = &self.nodes[k as usize].element;
                let centroid = (e.vertices[0] + e.vertices[1] + e.vertices[2]) / 3.0;
                self.cluster_irradiance(k, centroid, e.normal)
            })
            .collect();
        for (n, g) in self.nodes.iter_mut().zip(gathered) {
            n.gathered = g;
        }
        let mut change = 0.0;
        for r in 0..self.roots.len() + self.back_roots.len() {
            let root = self
                .roots
                .get(r)
                .copied()
                .unwrap_or_else(|| self.back_roots[r - self.roots.len()]);
            if root != NONE {
                let old = self.nodes[root as usize].radiance;
                let new = self.push_pull(root, from_clusters[root as usize]);
                change += self.nodes[root as usize].element.area as f64
                    * luminance((new - old).abs()) as f64;
            }
        }
        // Refine: every link the oracle now finds too coarse is replaced by finer ones.
        let mut coarse = self.coarse_cluster_links();
        // Read in parallel (serial, this scan of every link was 60% of the
        // solve's serial time on the Cornell box at ε 1e-5), removed in order.
        let removed: Vec<(u32, Vec<u32>)> = (0..self.nodes.len() as u32)
            .into_par_iter()
            .filter_map(|p| {
                let links = &self.nodes[p as usize].links;
                let sources: Vec<u32> = links
                    .iter()
                    .filter(|l| {
                        self.too_coarse(p, l) && (self.divisible(p) || self.divisible(l.source))
                    })
                    .map(|l| l.source)
                    .collect();
                (!sources.is_empty()).then_some((p, sources))
            })
            .collect();
        for (p, sources) in removed {
            // Forced: the oracle without the link's visibility would miss a
            // shadow boundary's finer threshold, and the pair would be
            // exchanged again only to be split then.
            coarse.extend(sources.iter().map(|&q| (p, q, true)));
            self.nodes[p as usize]
                .links
                .retain(|l| !sources.contains(&l.source));
        }
        self.link_all(geometry, coarse);
        change / self.emitted
    }

    /// Pushes `down` (light gathered by the ancestors) to the leaves and
    /// returns the node's area-weighted radiance.
    fn push_pull(&mut self, k: u32, down: Rgb) -> Rgb {
        let node = &self.nodes[k as usize];
        let total = down + node.gathered;
        let radiance = if node.children == NONE {
            node.element.emission + node.element.reflectance * total
        } else {
            let first = node.children;
            let mut sum = Rgb::ZERO;
            for c in first..first + 4 {
                sum += self.push_pull(c, total);
            }
            // Children have equal areas.
            sum / 4.0
        };
        self.nodes[k as usize].radiance = radiance;
        radiance
    }
}
