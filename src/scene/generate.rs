//! Random sequential addition: grains placed one by one at random, rejected when they
//! overlap a grain already placed. Deterministic for a given scene seed.

use super::error::Complainer;
use super::schema::{GeneratorSpec, RangeSpec, RegionSpec};
use super::{sphere_mass, Grains, SceneError};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Attempts per grain before the region counts as full.
pub const MAX_ATTEMPTS: usize = 20_000;

/// No grain: the end of a cell's list.
const NONE: u32 = u32::MAX;

/// A uniform grid of already placed grains for overlap queries during placement: a dense
/// array of cells over the box that holds the region and the grains already there, each cell
/// the head of a list threaded through the grains (`next`). Its cells are at least a grain's
/// diameter and grow until there are at most [`CELLS_PER_GRAIN`] per grain, so a region far
/// larger than its grains does not allocate a cell per diameter.
struct PlacementGrid {
    cell: f64,
    /// The grid's lower corner (m).
    origin: [f64; 3],
    /// Cells per axis.
    dims: [i64; 3],
    /// The last grain placed in each cell, or [`NONE`].
    head: Vec<u32>,
    /// The grain placed in the same cell before each grain, or [`NONE`].
    next: Vec<u32>,
    /// The lowest and highest cell holding a grain, per axis.
    occupied: [[i64; 2]; 3],
}

/// Most cells a placement grid makes per grain it may hold.
const CELLS_PER_GRAIN: f64 = 4.0;

impl PlacementGrid {
    /// A grid over `bounds` (lower and upper corners, m) for `capacity` grains, whose cells are
    /// at least `cell` (m) wide.
    fn new(bounds: [[f64; 3]; 2], cell: f64, capacity: usize) -> Self {
        let extent: Vec<f64> = (0..3).map(|a| (bounds[1][a] - bounds[0][a]).max(0.0)).collect();
        let volume: f64 = extent.iter().map(|e| e + cell).product();
        let cell = cell.max((volume / (CELLS_PER_GRAIN * capacity.max(1) as f64)).cbrt());
        let dims = [0, 1, 2].map(|a| (extent[a] / cell).floor() as i64 + 1);
        let cells = dims.iter().product::<i64>() as usize;
        PlacementGrid { cell, origin: bounds[0], dims, head: vec![NONE; cells], next: Vec::with_capacity(capacity), occupied: [[i64::MAX, i64::MIN]; 3] }
    }
    fn key(&self, p: [f64; 3]) -> [i64; 3] {
        [0, 1, 2].map(|a| ((p[a] - self.origin[a]) / self.cell).floor() as i64)
    }
    /// The index of cell `k`, or `None` outside the grid.
    fn index(&self, k: [i64; 3]) -> Option<usize> {
        (0..3).all(|a| (0..self.dims[a]).contains(&k[a])).then(|| ((k[2] * self.dims[1] + k[1]) * self.dims[0] + k[0]) as usize)
    }
    /// Adds the next grain (grains are added in id order, so its id is the count so far) at
    /// `p`, inside the grid.
    fn insert(&mut self, p: [f64; 3]) {
        let i = self.next.len() as u32;
        let k = self.key(p);
        let c = self.index(k).expect("a placed grain lies inside the grid's bounds");
        for (range, &k) in self.occupied.iter_mut().zip(&k) {
            *range = [range[0].min(k), range[1].max(k)];
        }
        self.next.push(self.head[c]);
        self.head[c] = i;
    }
    /// True when a sphere at `p` of radius `r` overlaps a placed grain, or a periodic image
    /// of one. Correct while `r` and every placed radius are at most `cell / 2`.
    fn overlaps(&self, grains: &Grains, p: [f64; 3], r: f64, periodic: &[Option<[f64; 2]>; 3]) -> bool {
        // Each axis' image shifts: none, or one period up and one down.
        let shifts = |a: usize| match periodic[a] {
            Some([lo, hi]) => ([0.0, hi - lo, lo - hi], 3),
            None => ([0.0; 3], 1),
        };
        let [(sx, nx), (sy, ny), (sz, nz)] = [shifts(0), shifts(1), shifts(2)];
        for &dx in &sx[..nx] {
            for &dy in &sy[..ny] {
                for &dz in &sz[..nz] {
                    if self.overlaps_here(grains, [p[0] + dx, p[1] + dy, p[2] + dz], r) {
                        return true;
                    }
                }
            }
        }
        false
    }

    fn overlaps_here(&self, grains: &Grains, p: [f64; 3], r: f64) -> bool {
        let k = self.key(p);
        // No grain in the 27 cells around `p` (most periodic images of a point inside).
        if (0..3).any(|a| k[a] + 1 < self.occupied[a][0] || k[a] - 1 > self.occupied[a][1]) {
            return false;
        }
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let Some(c) = self.index([k[0] + dx, k[1] + dy, k[2] + dz]) else { continue };
                    let mut j = self.head[c];
                    while j != NONE {
                        let q = grains.position[j as usize];
                        let d2 = (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2);
                        let s = r + grains.radius[j as usize];
                        if d2 < s * s {
                            return true;
                        }
                        j = self.next[j as usize];
                    }
                }
            }
        }
        false
    }
}

/// The lower and upper corners of a box holding `region` and every grain of `grains` (m).
fn bounds_of(region: &RegionSpec, grains: &Grains) -> [[f64; 3]; 2] {
    let mut b = region.bounds();
    for p in &grains.position {
        for a in 0..3 {
            b[0][a] = b[0][a].min(p[a]);
            b[1][a] = b[1][a].max(p[a]);
        }
    }
    b
}

/// `table.diameter` (`{ min, max }`, m): positive, `max` at least `min`.
pub(super) fn check_diameters(c: &Complainer, table: &str, d: &RangeSpec) -> Result<(), SceneError> {
    if !(d.min.is_finite() && d.min > 0.0) {
        return Err(c.invalid(format!("{table}.diameter.min"), d.min, "must be a positive number", "give the smallest diameter in metres"));
    }
    if !(d.max.is_finite() && d.max >= d.min) {
        return Err(c.invalid(format!("{table}.diameter.max"), d.max, format!("must be at least diameter.min = {:e}", d.min), "give the largest diameter in metres"));
    }
    Ok(())
}

/// Places generator `k`'s grains into `grains` (after those already there).
pub(super) fn place(
    c: &Complainer,
    k: usize,
    spec: &GeneratorSpec,
    material: u16,
    density: f64,
    seed: u64,
    periodic: &[Option<[f64; 2]>; 3],
    grains: &mut Grains,
) -> Result<(), SceneError> {
    let key = |s: &str| format!("generate[{k}].{s}");
    let d = &spec.diameter;
    check_diameters(c, &format!("generate[{k}]"), d)?;
    if spec.count == 0 {
        return Err(c.invalid(key("count"), 0, "must be at least 1", "give the number of grains"));
    }
    if !(spec.random_speed.is_finite() && spec.random_speed >= 0.0) {
        return Err(c.invalid(key("random_speed"), spec.random_speed, "must be zero or positive", "give a speed in m/s"));
    }
    let r_max_all = grains.radius.iter().copied().fold(0.5 * d.max, f64::max);
    let mut grid = PlacementGrid::new(bounds_of(&spec.region, grains), 2.0 * r_max_all, grains.len() + spec.count);
    for p in &grains.position {
        grid.insert(p.to_array());
    }
    // One stream per generator so that adding a generator leaves the others unchanged.
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ (0x9E37_79B9_7F4A_7C15u64.wrapping_mul(k as u64 + 1)));
    let mut solid = 0.0;
    for n in 0..spec.count {
        let diameter = if d.max > d.min { rng.random_range(d.min..d.max) } else { d.min };
        let r = 0.5 * diameter;
        let mut placed = None;
        for _ in 0..MAX_ATTEMPTS {
            let p = sample(c, k, &spec.region, r, &mut rng)?;
            if !grid.overlaps(grains, p, r, periodic) {
                placed = Some(p);
                break;
            }
        }
        let Some(p) = placed else {
            let fraction = solid / region_volume(&spec.region);
            return Err(c.invalid(
                key("count"),
                spec.count,
                format!("only {n} grains fit after {MAX_ATTEMPTS} attempts (solid fraction {fraction:.3}; random insertion jams near 0.3-0.35)"),
                "enlarge the region or lower the count",
            ));
        };
        let mut v = spec.velocity;
        if spec.random_speed > 0.0 {
            let dir = random_direction(&mut rng);
            for a in 0..3 {
                v[a] += spec.random_speed * dir[a];
            }
        }
        grid.insert(p);
        grains.push(r, sphere_mass(r, density), p.into(), v, glam::DVec3::ZERO, material);
        solid += 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
    }
    Ok(())
}

fn region_volume(region: &RegionSpec) -> f64 {
    match *region {
        RegionSpec::Box { min, max } => (0..3).map(|a| max[a] - min[a]).product(),
        RegionSpec::Cylinder { radius, z_min, z_max, .. } => std::f64::consts::PI * radius * radius * (z_max - z_min),
    }
}

/// A centre for a grain of radius `r` wholly inside the region.
fn sample(c: &Complainer, k: usize, region: &RegionSpec, r: f64, rng: &mut ChaCha8Rng) -> Result<[f64; 3], SceneError> {
    region.sample(r, rng).map_err(|(what, size)| c.invalid(format!("generate[{k}].region"), format!("{what} {size:e} m"), format!("cannot hold a grain of diameter {:e} m", 2.0 * r), "enlarge the region"))
}

impl RegionSpec {
    /// A centre, uniform, for a grain of radius `r` (m) wholly inside the region; the side
    /// (`"side"`, `"radius"` or `"height"`) and its size (m) where the region cannot hold one.
    pub(crate) fn sample(&self, r: f64, rng: &mut ChaCha8Rng) -> Result<[f64; 3], (&'static str, f64)> {
        match *self {
            RegionSpec::Box { min, max } => {
                let mut p = [0.0; 3];
                for a in 0..3 {
                    let (lo, hi) = (min[a] + r, max[a] - r);
                    if !(hi >= lo) {
                        return Err(("side", max[a] - min[a]));
                    }
                    p[a] = if hi > lo { rng.random_range(lo..hi) } else { lo };
                }
                Ok(p)
            }
            RegionSpec::Cylinder { center, radius, z_min, z_max } => {
                let rr = radius - r;
                if !(rr >= 0.0) {
                    return Err(("radius", radius));
                }
                if !(z_max - r >= z_min + r) {
                    return Err(("height", z_max - z_min));
                }
                let z = if z_max - r > z_min + r { rng.random_range(z_min + r..z_max - r) } else { z_min + r };
                loop {
                    let (x, y) = (rng.random_range(-1.0..1.0f64), rng.random_range(-1.0..1.0f64));
                    if x * x + y * y <= 1.0 {
                        return Ok([center[0] + rr * x, center[1] + rr * y, z]);
                    }
                }
            }
        }
    }

    /// Whether point `p` (m) lies inside the region (its boundary included).
    pub fn contains(&self, p: glam::DVec3) -> bool {
        match *self {
            RegionSpec::Box { min, max } => (0..3).all(|a| p[a] >= min[a] && p[a] <= max[a]),
            RegionSpec::Cylinder { center, radius, z_min, z_max } => {
                let (dx, dy) = (p.x - center[0], p.y - center[1]);
                dx * dx + dy * dy <= radius * radius && p.z >= z_min && p.z <= z_max
            }
        }
    }

    /// The lower and upper corners of the box around the region (m).
    pub fn bounds(&self) -> [[f64; 3]; 2] {
        match *self {
            RegionSpec::Box { min, max } => [min.to_array(), max.to_array()],
            RegionSpec::Cylinder { center, radius, z_min, z_max } => [[center[0] - radius, center[1] - radius, z_min], [center[0] + radius, center[1] + radius, z_max]],
        }
    }

    /// Its centre (m).
    pub fn centre(&self) -> glam::DVec3 {
        let [lo, hi] = self.bounds();
        glam::DVec3::new(0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2]))
    }
}

/// A unit vector uniform on the sphere (rejection from the cube).
pub(crate) fn random_direction(rng: &mut ChaCha8Rng) -> [f64; 3] {
    loop {
        let v: [f64; 3] = [rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)];
        let n2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        if n2 > 1e-6 && n2 <= 1.0 {
            let n = n2.sqrt();
            return [v[0] / n, v[1] / n, v[2] / n];
        }
    }
}

#[cfg(test)]
mod tests {
    //! The placement grid's overlap query against a brute-force test over every grain and its
    //! periodic images, so that what the grid skips (empty cells, images far from every grain)
    //! never changes an answer.
    use super::*;

    #[test]
    fn the_grids_overlap_query_is_the_brute_force_one() {
        // 150 grains at random in a box periodic in x and y (free to overlap one another: only
        // the queries are tested), queried at random points, many near a periodic face or
        // beyond the grains' extent in z.
        let (side, height, r) = (10.0e-3, 6.0e-3, 0.5e-3);
        let periodic = [Some([0.0, side]), Some([0.0, side]), None];
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut grains = Grains::default();
        let mut grid = PlacementGrid::new([[0.0; 3], [side, side, height]], 2.0 * r, 150);
        for _ in 0..150 {
            let p = [rng.random_range(0.0..side), rng.random_range(0.0..side), rng.random_range(0.0..height)];
            grid.insert(p);
            grains.push(r, 1.0, p.into(), glam::DVec3::ZERO, glam::DVec3::ZERO, 0);
        }
        let brute = |p: [f64; 3], rq: f64| {
            grains.position.iter().zip(&grains.radius).any(|(q, &rj)| {
                let d: Vec<f64> = (0..3)
                    .map(|a| {
                        let d = p[a] - q[a];
                        match periodic[a] {
                            Some([lo, hi]) => d - (hi - lo) * (d / (hi - lo)).round(),
                            None => d,
                        }
                    })
                    .collect();
                d.iter().map(|x| x * x).sum::<f64>() < (rq + rj) * (rq + rj)
            })
        };
        let (mut hits, mut misses) = (0, 0);
        for _ in 0..20_000 {
            let p = [rng.random_range(-0.2 * side..1.2 * side), rng.random_range(0.0..side), rng.random_range(-2.0e-3..height + 3.0e-3)];
            // x folded into the box, as placement's regions lie inside it.
            let p = [p[0].rem_euclid(side), p[1], p[2]];
            let expected = brute(p, r);
            assert_eq!(grid.overlaps(&grains, p, r, &periodic), expected, "query at {p:?}");
            if expected { hits += 1 } else { misses += 1 }
        }
        assert!(hits > 2000 && misses > 2000, "both answers exercised: {hits} overlaps, {misses} free");
    }
}
