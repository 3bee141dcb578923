//! Form factors between elements. F_ij = (1/A_i) ∫_i ∫_j cos θ_i cos θ_j
//! V / (π r²) dA_j dA_i, estimated two ways:
//!
//! - **ray casting**: n pairs of points (x on i, y on j) joined by a shadow
//!   ray. y is sampled uniformly in the solid angle Ω that j subtends from x
//!   (Arvo's spherical triangles, as light sampling does), so a pair
//!   estimates Ω cos θ_i / π times its visibility: the point-to-point kernel
//!   cos θ_i cos θ_j / (π r²) divided by y's density cos θ_j / (Ω r²). With
//!   y by area instead (where j is too small or too large in solid angle
//!   for the spherical construction) the kernel's 1/r² makes the variance
//!   barely finite for elements that share an edge: 5e-3 error at 4 096
//!   pairs on perpendicular unit squares, against 1e-4 by solid angle;
//! - **analytic**: n points x on i, the unoccluded point-to-polygon form
//!   factor of j from x by Lambert's contour integral, times the visibility
//!   of one point of j.
//!
//! The points x on i are those of a fixed quadrature rule ([`Rule`]), each
//! with its share of the n pairs; the points y on j come from the
//! renderer's Sobol sampler warped onto the triangle. Shadow rays leave and
//! reach surfaces by their error bounds, so nothing depends on the scene's
//! units.

use super::element::Element;
use crate::accel::Geometry;
use crate::math::{Rgb, gamma, ray_between};
use crate::sampling::spherical_triangle;
use crate::sampling::warp::{self, square_to_uniform_triangle};
use crate::sampling::{Sampler, SamplerKind};
use glam::{Vec2, Vec3A};
use std::f32::consts::PI;

/// How form factors are estimated.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FormFactorMethod {
    /// Point-to-point kernel between n point pairs, with visibility.
    RayCast,
    /// Point-to-polygon contour integral at n points, times visibility.
    #[default]
    Analytic,
}

impl FormFactorMethod {
    /// Samples per element pair unless asked otherwise: the count at which
    /// a form factor between unit-sized squares is within 1e-3. The
    /// contour integral is there at 16 points (its error is the quadrature
    /// rule's); point pairs take 256 (at 16: 2.7e-3 for perpendicular
    /// squares, 4.7e-3 for parallel 2 x 2 ones at distance 1; `tests/form_factors.rs`).
    pub fn default_samples(self) -> u32 {
        match self {
            FormFactorMethod::Analytic => 16,
            FormFactorMethod::RayCast => 256,
        }
    }
}

/// The unoccluded form factor from a differential area at `p` with unit
/// normal `n` to the polygon `vertices` (either winding), clipped to the
/// hemisphere above `p`: (1/2π) |Σ_edges n · γ_k|, γ_k the unit normal of
/// the plane through p and the edge, times the angle the edge subtends.
///
/// Polygons of up to 7 vertices (elements are triangles, quads at most).
pub fn point_to_polygon(p: Vec3A, n: Vec3A, vertices: &[Vec3A]) -> f32 {
    debug_assert!(vertices.len() <= 7, "clipping keeps at most 8 vertices");
    // Clip to n · (x - p) >= 0 (Sutherland–Hodgman against one plane).
    let mut clipped = [Vec3A::ZERO; 8];
    let mut count = 0;
    for (k, &a) in vertices.iter().enumerate() {
        let b = vertices[(k + 1) % vertices.len()];
        let (da, db) = (n.dot(a - p), n.dot(b - p));
        if da >= 0.0 && count < clipped.len() {
            clipped[count] = a - p;
            count += 1;
        }
        if (da >= 0.0) != (db >= 0.0) && count < clipped.len() {
            let t = da / (da - db);
            clipped[count] = a + t * (b - a) - p;
            count += 1;
        }
    }
    if count < 3 {
        return 0.0;
    }
    let mut sum = 0.0f64;
    for k in 0..count {
        let (a, b) = (clipped[k], clipped[(k + 1) % count]);
        let cross = a.cross(b);
        let length = cross.length();
        if length == 0.0 {
            continue;
        }
        let angle = angle_from(length, a.dot(b));
        sum += (n.dot(cross) / length * angle) as f64;
    }
    (sum.abs() / (2.0 * std::f64::consts::PI)) as f32
}

/// atan2(y, x) for y ≥ 0, the angle between two vectors from |a × b| and
/// a · b. libm's atan2f took 46% of hierarchical radiosity's time; this is
/// Cephes' atanf (a cubic in z² after reduction to |t| ≤ tan π/8), within
/// 2e-7 of it.
#[inline]
fn angle_from(y: f32, x: f32) -> f32 {
    use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};
    let (low, high) = (y.min(x.abs()), y.max(x.abs()));
    if high == 0.0 {
        return 0.0;
    }
    let t = low / high;
    let (offset, t) = if t > 0.414_213_56 {
        (FRAC_PI_4, (t - 1.0) / (t + 1.0))
    } else {
        (0.0, t)
    };
    let z = t * t;
    let poly = ((8.053_744_5e-2 * z - 1.387_768_6e-1) * z + 1.997_771_1e-1) * z - 3.333_294_9e-1;
    let mut angle = offset + t + t * z * poly;
    if y > x.abs() {
        angle = FRAC_PI_2 - angle;
    }
    if x < 0.0 { PI - angle } else { angle }
}

/// A uniform point of `element` and its rounding-error bound.
#[inline]
pub(crate) fn point_on(element: &Element, u: Vec2) -> (Vec3A, Vec3A) {
    point_at(element, square_to_uniform_triangle(u))
}

/// The point of `element` at barycentrics `b` (b1, b2) and its
/// rounding-error bound.
#[inline]
fn point_at(element: &Element, b: Vec2) -> (Vec3A, Vec3A) {
    let [a, v1, v2] = element.vertices;
    let (e1, e2) = (b.x * (v1 - a), b.y * (v2 - a));
    (a + e1 + e2, gamma(7) * (a.abs() + e1.abs() + e2.abs()))
}

/// A uniform point of the part of `j` in front of the plane through `x`
/// with normal `normal`, and its error bound; `None` where no part is.
/// Visibility sampled over all of j would count j's hidden part twice when
/// the contour integral has already clipped it away: a block's side
/// gathering from a floor element half under the block saw half its light.
fn point_in_front(x: Vec3A, normal: Vec3A, j: &Element, u: Vec2) -> Option<(Vec3A, Vec3A)> {
    let height = j.vertices.map(|v| normal.dot(v - x));
    if height.iter().all(|&h| h > 0.0) {
        return Some(point_on(j, u));
    }
    let mut clipped = [Vec3A::ZERO; 4];
    let mut count = 0;
    for a in 0..3 {
        let b = (a + 1) % 3;
        if height[a] > 0.0 {
            clipped[count] = j.vertices[a];
            count += 1;
        }
        if (height[a] > 0.0) != (height[b] > 0.0) {
            let t = height[a] / (height[a] - height[b]);
            clipped[count] = j.vertices[a] + t * (j.vertices[b] - j.vertices[a]);
            count += 1;
        }
    }
    let area = |a: Vec3A, b: Vec3A, c: Vec3A| (b - a).cross(c - a).length();
    let [p0, p1, p2, p3] = clipped;
    let (mut u, triangle) = match count {
        3 => (u, [p0, p1, p2]),
        4 => {
            let (first, second) = (area(p0, p1, p2), area(p0, p2, p3));
            let share = first / (first + second);
            if !share.is_finite() {
                return None;
            }
            if u.x < share {
                (Vec2::new(u.x / share, u.y), [p0, p1, p2])
            } else {
                (Vec2::new((u.x - share) / (1.0 - share), u.y), [p0, p2, p3])
            }
        }
        _ => return None,
    };
    u = u.min(Vec2::splat(1.0 - f32::EPSILON / 2.0));
    let b = square_to_uniform_triangle(u);
    let [a, v1, v2] = triangle;
    let y = a + b.x * (v1 - a) + b.y * (v2 - a);
    // The clipped corners are j's plane to a few more roundings.
    let scale = j.vertices[0].abs() + j.vertices[1].abs() + j.vertices[2].abs();
    Some((y, gamma(12) * scale))
}

/// A direction from `x` towards `j`, nearly proportional to the cosine at x
/// (`i_normal`) within the solid angle j subtends, 1 / its density (the
/// solid angle where the sampling is uniform), and the point of `j` the
/// direction reaches with its error bound;
/// `None` where the spherical construction is inaccurate (tiny or nearly
/// surrounding solid angles) or the direction misses j's plane.
#[inline]
fn toward(x: Vec3A, i_normal: Vec3A, j: &Element, u: Vec2) -> Option<(Vec3A, f32, Vec3A, Vec3A)> {
    let solid_angle = spherical_triangle::solid_angle(x, j.vertices);
    if !spherical_triangle::usable(solid_angle) {
        return None;
    }
    // The cosine at x warped in by a bilinear approximation over the
    // sample square, whose corners map to the triangle's vertices (pbrt-v4's
    // light sampling): what remains to estimate is nearly constant.
    let [a, b, c] = j
        .vertices
        .map(|v| i_normal.dot((v - x).normalize_or_zero()).max(0.01));
    let corners = [b, b, a, c];
    let warped = warp::square_to_bilinear(u, corners);
    let (w, _) = spherical_triangle::sample(x, j.vertices, warped)?;
    let bilinear = warp::square_to_bilinear_pdf(warped, corners);
    let denominator = j.normal.dot(w);
    let t = j.normal.dot(j.vertices[0] - x) / denominator;
    if !(t > 0.0 && t.is_finite()) {
        return None;
    }
    let y = x + t * w;
    // A ray-plane intersection: a few roundings of x, t w and the plane's
    // offset.
    let error = gamma(12) * (x.abs() + (t * w).abs() + j.vertices[0].abs());
    Some((w, solid_angle / bilinear, y, error))
}

/// Whether `j` lies entirely behind `i`'s plane or `i` behind `j`'s (then
/// F_ij = 0), measured relative to the elements' sizes.
pub fn faces(i: &Element, j: &Element) -> bool {
    let above = |from: &Element, to: &Element| {
        let scale = from.area.sqrt().max(to.area.sqrt());
        to.vertices
            .iter()
            .any(|v| from.normal.dot(*v - from.vertices[0]) > 1e-5 * scale)
    };
    above(i, j) && above(j, i)
}

/// F_ij from `n` point pairs. The points on i are those of a fixed rule
/// ([`Rule`]), the same for every form factor of row i: with the contour
/// integral, whose values at a point sum to 1 over a closed surrounding,
/// the row sums of a closed scene are 1 to rounding. The points on j, one
/// per pair, are Sobol points per point of i and depend on `keys.1` (the
/// pair's key); `keys.0` (the gatherer's) picked the points of i when they
/// were random and no longer changes anything. Returns the estimate and the
/// shadow rays cast.
pub fn element_to_element(
    geometry: &Geometry,
    i: &Element,
    j: &Element,
    method: FormFactorMethod,
    n: u32,
    keys: (u32, u32),
) -> Exchange {
    probed_element_to_element(geometry, (i, j), method, n, keys, 0, |_| false)
}

/// [`element_to_element`], its first points (those of at least `probe`
/// pairs) shown to `split` first: where it finds from them that the link
/// will be split anyway, the rest are not taken and the probe's exchange is
/// returned. Otherwise the rest continue the probe's sums, to exactly the
/// whole estimate.
pub fn probed_element_to_element(
    geometry: &Geometry,
    (i, j): (&Element, &Element),
    method: FormFactorMethod,
    n: u32,
    (_, key_pair): (u32, u32),
    probe: u32,
    split: impl Fn(&Exchange) -> bool,
) -> Exchange {
    if !faces(i, j) {
        return Exchange::default();
    }
    let n = n.max(1);
    let rule = Rule::for_pairs(n);
    let mut sums = ExchangeSums::default();
    let mut first = 0;
    if probe > 0 {
        while first < rule.len() && rule.pairs_before(first, n) < probe.min(n) {
            first += 1;
        }
        sums = exchange_points(
            (geometry, (i, j), method, key_pair),
            rule,
            n,
            0..first,
            sums,
        );
        let early = sums.exchange();
        if split(&early) {
            return early;
        }
    }
    exchange_points(
        (geometry, (i, j), method, key_pair),
        rule,
        n,
        first..rule.len(),
        sums,
    )
    .exchange()
}

/// The points of i at which an exchange is evaluated: a symmetric rule on
/// the triangle (Dunavant's of degree 2 with 3 points or degree 4 with 6),
/// on i itself or on each of its 4^level subtriangles, so that the most
/// points serve n pairs. The contour integral's unoccluded form factor is
/// smooth over i: between unit squares the 6 points are within 2.5e-5 of
/// the closed form (parallel) and 6.6e-6 (perpendicular), 16 stratified
/// random points within 2-6e-3 (RMS), and over random Cornell-like element
/// pairs 6 points beat 16 random ones 3-1000 times, more the farther apart.
#[derive(Clone, Copy, Debug)]
struct Rule {
    base: &'static [([f32; 3], f32)],
    level: u32,
}

/// Dunavant's degree-2 rule: barycentrics and weights.
const THREE_POINTS: [([f32; 3], f32); 3] = [
    ([2.0 / 3.0, 1.0 / 6.0, 1.0 / 6.0], 1.0 / 3.0),
    ([1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0], 1.0 / 3.0),
    ([1.0 / 6.0, 1.0 / 6.0, 2.0 / 3.0], 1.0 / 3.0),
];

/// Dunavant's degree-4 rule.
const SIX_POINTS: [([f32; 3], f32); 6] = {
    let (a, b, w) = (0.445_948_5, 0.108_103_02, 0.223_381_59);
    let (c, d, v) = (0.091_576_214, 0.816_847_6, 0.109_951_744);
    [
        ([a, a, b], w),
        ([a, b, a], w),
        ([b, a, a], w),
        ([c, c, d], v),
        ([c, d, c], v),
        ([d, c, c], v),
    ]
};

/// The centroid.
const ONE_POINT: [([f32; 3], f32); 1] = [([1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0], 1.0)];

/// Pairs per point below which a rule is not subdivided further.
const PAIRS_PER_POINT: u32 = 4;

/// Deepest subdivision of a rule (6 x 4^5 points).
const MAX_RULE_LEVEL: u32 = 5;

impl Rule {
    /// The rule for n pairs: at least one pair per point, and subdivided
    /// only while each point keeps [`PAIRS_PER_POINT`]. The rule's error
    /// falls fast with its points (2x2 squares: 9e-4 at 6, 1e-5 at 24); the
    /// error of a point's own Sobol pairs (ray casting's inner integral,
    /// visibility) falls nearly as their number, but only as its square root
    /// over more points of few pairs each.
    fn for_pairs(n: u32) -> Rule {
        let base: &'static [([f32; 3], f32)] = match n {
            0..=2 => &ONE_POINT,
            3..=5 => &THREE_POINTS,
            _ => &SIX_POINTS,
        };
        let mut level = 0;
        while level < MAX_RULE_LEVEL
            && (base.len() as u32) << (2 * (level + 1)) <= n / PAIRS_PER_POINT
        {
            level += 1;
        }
        Rule { base, level }
    }

    fn len(&self) -> u32 {
        (self.base.len() as u32) << (2 * self.level)
    }

    /// The pairs of point k: n spread as evenly as the points allow.
    fn pairs(&self, k: u32, n: u32) -> u32 {
        n / self.len() + u32::from(k < n % self.len())
    }

    /// The pairs of the points before k.
    fn pairs_before(&self, k: u32, n: u32) -> u32 {
        k * (n / self.len()) + k.min(n % self.len())
    }

    /// Point k's barycentrics (b1, b2) in the element and its weight.
    fn point(&self, k: u32) -> (Vec2, f32) {
        let (corner, weight) = self.base[(k % self.base.len() as u32) as usize];
        // The subtriangle: base-4 digits of k / base, coarsest first, in the
        // numbering of `mesh::children`.
        let mut t = [Vec2::ZERO, Vec2::X, Vec2::Y];
        let sub = k / self.base.len() as u32;
        for d in (0..self.level).rev() {
            t = super::mesh::children(t)[(sub >> (2 * d) & 3) as usize];
        }
        let b = corner[0] * t[0] + corner[1] * t[1] + corner[2] * t[2];
        (b, weight / (1u32 << (2 * self.level)) as f32)
    }
}

/// The running sums of an exchange's points: a first few can decide that
/// a link is to be split before the rest are taken, and the rest continue
/// from them to exactly the whole estimate.
#[derive(Clone, Copy, Debug, Default)]
struct ExchangeSums {
    sum: f64,
    /// Weights of the points taken (1 once all are).
    weights: f64,
    rays: u32,
    /// Pairs whose visibility is known: by a ray, or dark
    /// because i's point lies behind j's plane. A link some of whose pairs
    /// are dark that way is partly visible, so refinement and the smooth
    /// display's vertex rays find the edge of j's plane (a block standing
    /// on the floor).
    tested: u32,
    visible: u32,
}

impl ExchangeSums {
    fn exchange(&self) -> Exchange {
        Exchange {
            f: if self.weights > 0.0 {
                (self.sum / self.weights) as f32
            } else {
                0.0
            },
            rays: self.rays,
            visibility: if self.tested == 0 {
                1.0
            } else {
                self.visible as f32 / self.tested as f32
            },
        }
    }
}

/// What every point of one exchange shares.
type Pass<'a> = (
    &'a Geometry,
    (&'a Element, &'a Element),
    FormFactorMethod,
    u32,
);

/// The rule's points `points` of F_ij (n pairs in all), continuing from
/// `sums`; i and j face each other.
fn exchange_points(
    (geometry, (i, j), method, key_pair): Pass,
    rule: Rule,
    n: u32,
    points: std::ops::Range<u32>,
    mut sums: ExchangeSums,
) -> ExchangeSums {
    for k in points {
        let (b, weight) = rule.point(k);
        let pairs = rule.pairs(k, n);
        sums.weights += f64::from(weight);
        let (x, x_error) = point_at(i, b);
        // Each point's pairs are a Sobol sequence of their own.
        let mut on_j = Sampler::new(SamplerKind::Sobol, 0x5eed_0001, pairs);
        let key = key_pair ^ k.wrapping_mul(0x9e37_79b9);
        let mut arrived = 0.0f64;
        match method {
            FormFactorMethod::Analytic => {
                // j is one-sided: from behind its plane (a floor point under
                // a block, behind the block's side) it sends nothing. The
                // contour integral clips to x's hemisphere only.
                if j.normal.dot(x - j.vertices[0]) <= 0.0 {
                    sums.tested += pairs;
                    continue;
                }
                let value = point_to_polygon(x, i.normal, &j.vertices);
                if value == 0.0 {
                    continue;
                }
                let mut seen = 0;
                for r in 0..pairs {
                    on_j.start(key, r);
                    let Some((y, y_error)) = point_in_front(x, i.normal, j, on_j.next_2d()) else {
                        continue;
                    };
                    seen += u32::from(visible(geometry, (x, x_error, i), (y, y_error, j)));
                    sums.rays += 1;
                    sums.tested += 1;
                }
                sums.visible += seen;
                arrived = f64::from(value) * f64::from(seen) / f64::from(pairs);
            }
            FormFactorMethod::RayCast => {
                for r in 0..pairs {
                    on_j.start(key, r);
                    let u_j = on_j.next_2d();
                    let (value, y, y_error) = match toward(x, i.normal, j, u_j) {
                        Some((w, solid_angle, y, y_error)) => {
                            let cos_i = i.normal.dot(w);
                            if cos_i <= 0.0 || j.normal.dot(w) >= 0.0 {
                                continue;
                            }
                            (solid_angle * cos_i / PI, y, y_error)
                        }
                        None => {
                            let (y, y_error) = point_on(j, u_j);
                            let d = y - x;
                            let r2 = d.length_squared();
                            let (cos_i, cos_j) = (i.normal.dot(d), -j.normal.dot(d));
                            if cos_i <= 0.0 || cos_j <= 0.0 || r2 == 0.0 {
                                continue;
                            }
                            (cos_i * cos_j / (PI * r2 * r2) * j.area, y, y_error)
                        }
                    };
                    if value == 0.0 {
                        continue;
                    }
                    sums.tested += 1;
                    sums.rays += 1;
                    if visible(geometry, (x, x_error, i), (y, y_error, j)) {
                        sums.visible += 1;
                        arrived += f64::from(value);
                    }
                }
                arrived /= f64::from(pairs);
            }
        }
        sums.sum += f64::from(weight) * arrived;
    }
    sums
}

/// Whether the shadow ray from x on i to y on j arrives.
#[inline(always)]
fn visible(
    geometry: &Geometry,
    (x, x_error, i): (Vec3A, Vec3A, &Element),
    (y, y_error, j): (Vec3A, Vec3A, &Element),
) -> bool {
    !geometry.occluded(&ray_between(x, x_error, i.normal, y, y_error, j.normal))
}

/// Points per element (or node) for its [`exposure`].
pub const EXPOSURE_POINTS: u32 = 16;

/// The radiance an element of mean radiance `radiance` sends: its reflected
/// light spread over the share `exposure` of it that light can leave from
/// (an element's mean counts its hidden part's darkness, but nothing leaves
/// from there). Below 1/16 the reflected light is not spread further.
#[inline]
pub fn sent_radiance(radiance: Rgb, emission: Rgb, exposure: f32) -> Rgb {
    emission + (radiance - emission) / exposure.max(1.0 / 16.0)
}

/// The share of element `e` from which light can leave: of `n` stratified
/// points, those where one of up to four cosine-distributed rays escapes or
/// meets a surface from its front. A floor point under a block sees only the
/// block's inside (back faces) and counts as hidden; so does the ceiling
/// behind a light hung just below it. Returns the share and the rays cast.
pub fn exposure(geometry: &Geometry, two_sided: &[bool], e: &Element, n: u32) -> (f32, u32) {
    let mut on_e = Sampler::new(SamplerKind::Stratified, 0x5eed_0003, n);
    let (mut exposed, mut rays) = (0, 0);
    for k in 0..n {
        on_e.start(0, k);
        let (x, x_error) = point_on(e, on_e.next_2d());
        let (open, cast) = open_at(geometry, two_sided, x, x_error, e.normal, on_e.next_2d());
        exposed += u32::from(open);
        rays += cast;
    }
    (exposed as f32 / n as f32, rays)
}

/// Whether light can leave the point `x` (error bound `x_error`, normal
/// `normal`): one of four cosine-distributed rays, one per quadrant of the
/// square jittered by `jitter`, escapes or meets a surface from its front,
/// or the back of a triangle that is `two_sided` (its back is a patch).
/// Returns that and the rays cast.
pub fn open_at(
    geometry: &Geometry,
    two_sided: &[bool],
    x: Vec3A,
    x_error: Vec3A,
    normal: Vec3A,
    jitter: Vec2,
) -> (bool, u32) {
    let frame = crate::math::Frame::from_normal(normal);
    for d in 0..4 {
        let u = (Vec2::new((d % 2) as f32, (d / 2) as f32) + jitter) * 0.5;
        let w = frame.to_world(warp::square_to_cosine_hemisphere(u));
        let origin = crate::math::offset_ray_origin(x, x_error, normal, w);
        let open = geometry
            .intersect(&crate::math::Ray::new(origin, w))
            .is_none_or(|hit| {
                hit.normal.dot(w) < 0.0 || two_sided.get(hit.primitive as usize) == Some(&true)
            });
        if open {
            return (true, d + 1);
        }
    }
    (false, 4)
}

/// The share of `n` shadow rays from the point `x` (normal `normal`) to
/// stratified points of `j` that arrive: visibility at a point, where a
/// link's share is the mean over its gatherer.
pub fn point_visibility(geometry: &Geometry, x: Vec3A, normal: Vec3A, j: &Element, n: u32) -> f32 {
    let mut on_j = Sampler::new(SamplerKind::Stratified, 0x5eed_0002, n);
    let x_error = gamma(7) * x.abs();
    let mut visible = 0;
    for k in 0..n {
        on_j.start(0, k);
        let Some((y, y_error)) = point_in_front(x, normal, j, on_j.next_2d()) else {
            return 0.0;
        };
        let ray = ray_between(x, x_error, normal, y, y_error, j.normal);
        visible += u32::from(!geometry.occluded(&ray));
    }
    visible as f32 / n as f32
}

/// What [`element_to_element`] found.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Exchange {
    /// The form factor F_ij.
    pub f: f32,
    /// Shadow rays cast.
    pub rays: u32,
    /// The share of them that arrived (1 when none was needed): the
    /// hierarchy's smooth display scales point-to-polygon form factors by it.
    pub visibility: f32,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fast_angle_matches_atan2_over_the_upper_half_plane() {
        let mut worst = 0.0f32;
        for k in 0..=100_000 {
            let phi = std::f32::consts::PI * k as f32 / 100_000.0;
            for r in [1e-3f32, 1.0, 1e3] {
                let (y, x) = (r * phi.sin().abs(), r * phi.cos());
                worst = worst.max((angle_from(y, x) - y.atan2(x)).abs());
            }
        }
        assert!(worst < 5e-7, "{worst}");
        assert_eq!(angle_from(0.0, 0.0), 0.0);
    }

    #[test]
    fn a_point_under_a_huge_square_sees_all_of_the_hemisphere() {
        let big = 1e4;
        let square = [
            Vec3A::new(-big, -big, 1.0),
            Vec3A::new(big, -big, 1.0),
            Vec3A::new(big, big, 1.0),
            Vec3A::new(-big, big, 1.0),
        ];
        let f = point_to_polygon(Vec3A::ZERO, Vec3A::Z, &square);
        assert!((f - 1.0).abs() < 1e-3, "{f}");
        // A disc of radius R at height h: R² / (h² + R²); a 64-gon is close.
        let (r, h) = (1.0f32, 1.0f32);
        let disc: Vec<Vec3A> = (0..64)
            .map(|k| {
                let a = k as f32 / 64.0 * 2.0 * PI;
                Vec3A::new(r * a.cos(), r * a.sin(), h)
            })
            .collect();
        // As a fan of 64 triangles (form factors add over a partition).
        let fan = |n: Vec3A| -> f32 {
            (0..64)
                .map(|k| {
                    point_to_polygon(
                        Vec3A::ZERO,
                        n,
                        &[Vec3A::new(0.0, 0.0, h), disc[k], disc[(k + 1) % 64]],
                    )
                })
                .sum()
        };
        let f = fan(Vec3A::Z);
        let polygon_share = (64.0 / (2.0 * PI) * (2.0 * PI / 64.0).sin()) as f32;
        assert!((f - 0.5 * polygon_share).abs() < 1e-3, "{f}");
        // Behind the point: nothing.
        assert_eq!(fan(-Vec3A::Z), 0.0);
    }
}
