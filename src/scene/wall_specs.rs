//! `[[wall]]` tables into validated walls: each wall kind's geometry checked, the servo box and
//! the piston found, the grains checked to start inside and clear of them, and the container's
//! cross-section.

use super::*;

/// Walls before the piston's defaults are known.
pub(super) struct PendingWall {
    wall: Wall,
    piston_mass: Option<f64>,
    piston_area: Option<f64>,
    /// The servo box this plane belongs to: (pressure, gain, max speed).
    servo: Option<(f64, f64, f64)>,
}

pub(super) fn validate_walls(
    c: &Complainer,
    f: &SceneFile,
    material_of: &dyn Fn(String, &str) -> Result<u16, SceneError>,
) -> Result<Vec<PendingWall>, SceneError> {
    let mut out = Vec::new();
    let driven = |name: String, shape: WallShape, material: u16, drive: WallDrive| PendingWall { wall: Wall { name, shape, material, drive, present: true }, piston_mass: None, piston_area: None, servo: None };
    let plain = |name: String, shape: WallShape, material: u16| driven(name, shape, material, WallDrive::default());
    for (i, w) in f.walls.iter().enumerate() {
        let key = |k: &str| format!("wall[{i}].{k}");
        let name = match w {
            WallSpec::Plane { name, .. } | WallSpec::Box { name, .. } | WallSpec::Cylinder { name, .. } | WallSpec::Mesh { name, .. } => name.as_deref(),
            _ => None,
        };
        let name = match name {
            Some(n) if n.is_empty() || n.contains('.') || n.contains('[') => {
                return Err(c.invalid(key("name"), format!("\"{n}\""), "must be a word without dots or brackets", "give a name such as \"gate\""));
            }
            Some(n) if f.walls[..i].iter().any(|o| matches!(o, WallSpec::Plane { name: Some(m), .. } | WallSpec::Box { name: Some(m), .. } | WallSpec::Cylinder { name: Some(m), .. } | WallSpec::Mesh { name: Some(m), .. } if m == n)) => {
                return Err(c.invalid(key("name"), format!("\"{n}\""), "is used by an earlier wall", "give each wall its own name"));
            }
            Some(n) => n.to_string(),
            None => format!("wall[{i}]"),
        };
        match w {
            WallSpec::Plane { material, point, normal, velocity, angular_velocity, .. } => {
                let m = material_of(key("material"), material)?;
                let point = finite3(c, &key("point"), *point)?;
                let normal = finite3(c, &key("normal"), *normal)?;
                let len = (normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]).sqrt();
                if len == 0.0 {
                    return Err(c.invalid(key("normal"), format!("{:?}", normal.to_array()), "is the zero vector", "give the direction into the domain, e.g. [0, 0, 1]"));
                }
                let normal = DVec3::new(normal[0] / len, normal[1] / len, normal[2] / len);
                let shape = WallShape::Plane { point, normal };
                let drive = turning(drive_of(c, &format!("wall[{i}]"), *velocity, *angular_velocity, SpinRule::AnyAxis)?, &shape);
                out.push(driven(name, shape, m, drive));
            }
            WallSpec::Box { material, min, max, open_top, velocity, .. } => {
                let m = material_of(key("material"), material)?;
                let (lo, hi) = (finite3(c, &key("min"), *min)?, finite3(c, &key("max"), *max)?);
                if (0..3).any(|k| hi[k] <= lo[k]) {
                    return Err(c.invalid(key("max"), format!("{:?}", hi.to_array()), format!("must exceed min {:?} on every axis", lo.to_array()), "give the upper corner above the lower one"));
                }
                let faces: [(&str, DVec3, DVec3); 6] = [
                    ("bottom", lo, DVec3::new(0.0, 0.0, 1.0)),
                    ("top", hi, DVec3::new(0.0, 0.0, -1.0)),
                    ("x_min", lo, DVec3::new(1.0, 0.0, 0.0)),
                    ("x_max", hi, DVec3::new(-1.0, 0.0, 0.0)),
                    ("y_min", lo, DVec3::new(0.0, 1.0, 0.0)),
                    ("y_max", hi, DVec3::new(0.0, -1.0, 0.0)),
                ];
                for (face, point, normal) in faces {
                    if *open_top && face == "top" {
                        continue;
                    }
                    let drive = drive_of(c, &format!("wall[{i}]"), *velocity, None, SpinRule::Refused)?;
                    out.push(driven(format!("{name}.{face}"), WallShape::Plane { point, normal }, m, drive));
                }
            }
            WallSpec::ServoBox { material, min, max, pressure, gain, max_speed } => {
                let m = material_of(key("material"), material)?;
                let (lo, hi) = (finite3(c, &key("min"), *min)?, finite3(c, &key("max"), *max)?);
                if (0..3).any(|k| hi[k] <= lo[k]) {
                    return Err(c.invalid(key("max"), format!("{:?}", hi.to_array()), format!("must exceed min {:?} on every axis", lo.to_array()), "give the upper corner above the lower one"));
                }
                if out.iter().any(|p: &PendingWall| p.servo.is_some()) {
                    return Err(c.invalid(key("type"), "\"servo_box\"", "a scene has at most one servo box", "remove the extra one"));
                }
                let pressure = non_negative(c, &key("pressure"), *pressure, "give the target pressure in Pa")?;
                let max_speed = positive(c, &key("max_speed"), max_speed.unwrap_or(DEFAULT_SERVO_SPEED), "give the largest wall speed in m/s")?;
                let gain = positive(c, &key("gain"), gain.unwrap_or(max_speed / pressure.max(SERVO_PRESSURE_FLOOR)), "give the wall speed per pressure error in m/(s Pa)")?;
                let faces: [(&str, DVec3, DVec3); 6] = [
                    ("x_min", lo, DVec3::new(1.0, 0.0, 0.0)),
                    ("x_max", hi, DVec3::new(-1.0, 0.0, 0.0)),
                    ("y_min", lo, DVec3::new(0.0, 1.0, 0.0)),
                    ("y_max", hi, DVec3::new(0.0, -1.0, 0.0)),
                    ("z_min", lo, DVec3::new(0.0, 0.0, 1.0)),
                    ("z_max", hi, DVec3::new(0.0, 0.0, -1.0)),
                ];
                for (face, point, normal) in faces {
                    let mut w = plain(format!("wall[{i}].{face}"), WallShape::Plane { point, normal }, m);
                    w.servo = Some((pressure, gain, max_speed));
                    out.push(w);
                }
            }
            WallSpec::Cylinder { material, center, radius, velocity, angular_velocity, .. } => {
                let m = material_of(key("material"), material)?;
                let radius = positive(c, &key("radius"), *radius, "give the radius in metres")?;
                let drive = drive_of(c, &format!("wall[{i}]"), *velocity, *angular_velocity, SpinRule::Along(DVec3::Z, "the cylinder's axis (z)"))?;
                out.push(driven(name, WallShape::Cylinder { center: *center, radius }, m, drive));
            }
            WallSpec::Mesh { material, file, scale, rotation, offset, velocity, angular_velocity, center, .. } => {
                let m = material_of(key("material"), material)?;
                let scale = positive(c, &key("scale"), scale.unwrap_or(1.0), "give the factor from the file's units to metres, e.g. 0.001 for millimetres")?;
                let rotation_deg = finite3(c, &key("rotation"), rotation.unwrap_or_default())?;
                let offset = finite3(c, &key("offset"), offset.unwrap_or_default())?;
                let path = c.file.parent().unwrap_or(std::path::Path::new("")).join(file);
                let mesh = crate::mesh::read::read_stl(&path, &crate::mesh::MeshPlacement { scale, rotation_deg, offset })
                    .map_err(|e| c.invalid(key("file"), format!("\"{file}\""), format!("{}: {}", e.file.display(), e.problem), e.fix))?;
                let pivot = center.map(|p| finite3(c, &key("center"), p)).transpose()?.unwrap_or(offset);
                let index = out.iter().filter(|p: &&PendingWall| matches!(p.wall.shape, WallShape::Mesh { .. })).count() as u32;
                let shape = WallShape::Mesh { mesh: std::sync::Arc::new(mesh), index, pivot };
                let drive = turning(drive_of(c, &format!("wall[{i}]"), *velocity, *angular_velocity, SpinRule::AnyAxis)?, &shape);
                out.push(driven(name, shape, m, drive));
            }
            WallSpec::Piston { material, z, pressure, mass, area } => {
                let m = material_of(key("material"), material)?;
                if !z.is_finite() {
                    return Err(c.invalid(key("z"), z, "must be finite", "give the initial height in metres"));
                }
                let pressure = non_negative(c, &key("pressure"), *pressure, "give the pressure in Pa")?;
                let piston_mass = mass.map(|v| positive(c, &key("mass"), v, "give the mass in kg or leave it out")).transpose()?;
                let piston_area = area.map(|v| positive(c, &key("area"), v, "give the area in m^2 or leave it out")).transpose()?;
                if out.iter().any(|p: &PendingWall| matches!(p.wall.shape, WallShape::Piston { .. })) {
                    return Err(c.invalid(key("type"), "\"piston\"", "a scene has at most one piston", "remove the extra piston"));
                }
                out.push(PendingWall {
                    wall: Wall { name: format!("wall[{i}]"), shape: WallShape::Piston { z: *z, pressure, mass: 0.0, area: 0.0 }, material: m, drive: WallDrive::default(), present: true },
                    piston_mass,
                    piston_area,
                    servo: None,
                });
            }
        }
    }
    Ok(out)
}

/// Which spins a wall takes.
#[derive(Clone, Copy)]
pub(super) enum SpinRule {
    /// Any axis through its pivot (a plane, a mesh).
    AnyAxis,
    /// Only along this axis of symmetry, named so in errors (a cylinder spins in place).
    Along(DVec3, &'static str),
    /// None: it only translates (a box's faces).
    Refused,
}

/// `drive` for a wall of `shape`, marked where its spin turns it.
fn turning(drive: WallDrive, shape: &WallShape) -> WallDrive {
    WallDrive { turns: crate::walls::turns_with(shape, drive.angular_velocity), ..drive }
}

/// The prescribed motion given at `at` (`wall[0]`, `stage[2].walls.gate`): `velocity` and
/// `angular_velocity` (finite; a spin as `spin` allows).
pub(super) fn drive_of(c: &Complainer, at: &str, velocity: Option<DVec3>, angular_velocity: Option<DVec3>, spin: SpinRule) -> Result<WallDrive, SceneError> {
    let key = |k: &str| format!("{at}.{k}");
    let velocity = velocity.map(|v| finite3(c, &key("velocity"), v)).transpose()?.unwrap_or_default();
    let angular_velocity = angular_velocity.map(|w| finite3(c, &key("angular_velocity"), w)).transpose()?.unwrap_or_default();
    let given = format!("{:?}", angular_velocity.to_array());
    match spin {
        SpinRule::AnyAxis => {}
        SpinRule::Refused if angular_velocity != DVec3::ZERO => {
            return Err(c.invalid(key("angular_velocity"), given, "is given to a box, which only translates", "give it a velocity only, or build the box as a mesh wall, which turns"));
        }
        SpinRule::Refused => {}
        SpinRule::Along(axis, axis_name) => {
            if angular_velocity.cross(axis).length() > crate::walls::SPIN_OFF_AXIS * angular_velocity.length() {
                return Err(c.invalid(
                    key("angular_velocity"),
                    given,
                    format!("is not along {axis_name} {:?}: the wall spins about its own axis only", axis.to_array()),
                    format!("give a multiple of {:?} (rad/s), or a mesh wall, which turns about any axis", axis.to_array()),
                ));
            }
        }
    }
    Ok(WallDrive { velocity, angular_velocity, turns: false })
}

/// Fills in the piston's default mass (total grain mass) and area (cross-section of the
/// cylinder, or of a box's side walls).
/// The servo box among the walls, if any.
pub(super) fn servo_box(pending: &[PendingWall]) -> Option<ServoBox> {
    let first = pending.iter().position(|p| p.servo.is_some())?;
    let (pressure, gain, max_speed) = pending[first].servo?;
    Some(ServoBox { walls: [0, 1, 2, 3, 4, 5].map(|k| first + k), pressure, gain, max_speed })
}

pub(super) fn finish_walls(c: &Complainer, pending: Vec<PendingWall>, grains: &Grains, periodic: &[Option<[f64; 2]>; 3]) -> Result<Vec<Wall>, SceneError> {
    let section = cross_section(pending.iter().map(|p| &p.wall.shape), periodic);
    let total_mass: f64 = grains.mass.iter().sum();
    let mut out = Vec::with_capacity(pending.len());
    for p in pending {
        let mut wall = p.wall;
        if let WallShape::Piston { mass, area, .. } = &mut wall.shape {
            *mass = p.piston_mass.unwrap_or(total_mass);
            *area = match p.piston_area.or(section) {
                Some(a) => a,
                None => {
                    return Err(c.invalid(format!("{}.area", wall.name), "(none)", "the piston's area cannot be inferred without a cylinder or box wall", "give `area` in m^2"));
                }
            };
        }
        out.push(wall);
    }
    Ok(out)
}

/// Horizontal cross-section (m^2) of a container: a cylinder wall's, or that of the side
/// planes of a box or the periods of the x and y axes; `None` when nothing bounds one.
pub fn cross_section<'a>(shapes: impl Iterator<Item = &'a WallShape> + Clone, periodic: &[Option<[f64; 2]>; 3]) -> Option<f64> {
    let cylinder = shapes.clone().find_map(|s| match *s {
        WallShape::Cylinder { radius, .. } => Some(std::f64::consts::PI * radius * radius),
        _ => None,
    });
    cylinder.or_else(|| {
        let side = |n: DVec3| {
            shapes.clone().find_map(|s| match *s {
                WallShape::Plane { point, normal } if normal == n => Some(point),
                _ => None,
            })
        };
        let span = |a: usize, n: DVec3| match periodic[a] {
            Some([lo, hi]) => Some(hi - lo),
            None => {
                let mut m = n;
                m[a] = -n[a];
                Some(side(m)?[a] - side(n)?[a])
            }
        };
        Some(span(0, DVec3::new(1.0, 0.0, 0.0))? * span(1, DVec3::new(0.0, 1.0, 0.0))?)
    })
}

/// Signed distance (m) from a point to a wall's surface at its initial position, positive on
/// the grains' side (either side of a mesh).
pub fn wall_distance(shape: &WallShape, p: DVec3) -> f64 {
    match shape {
        WallShape::Mesh { mesh, .. } => mesh.distance(p),
        _ => crate::walls::WallGeom::<f64>::of(shape).frame(crate::real::Vec3::of(p), crate::real::Vec3::ZERO).1,
    }
}

/// Signed distance (m) from a point to a wall's surface where it stands now (`geom`, as a
/// frame has it; `shape` the scene's), positive on the grains' side.
pub fn wall_distance_now(shape: &WallShape, geom: &crate::walls::WallGeom<f64>, p: DVec3) -> f64 {
    match (shape, geom) {
        (WallShape::Mesh { mesh, .. }, crate::walls::WallGeom::Mesh { pose, .. }) => mesh.distance(pose.local(crate::real::Vec3::of(p), crate::real::Vec3::ZERO).f64()),
        (_, geom) => geom.frame(crate::real::Vec3::of(p), crate::real::Vec3::ZERO).1,
    }
}

/// Grains may not start overlapping a wall (grains read from a file: by more than
/// [`READ_WALL_OVERLAP`]) or (listed grains) each other: the first step would release the
/// stored energy at once.
pub(super) fn check_overlaps(c: &Complainer, origins: &Origins, grains: &Grains, walls: &[Wall]) -> Result<(), SceneError> {
    let listed = origins.listed;
    let origin = |i: usize| origins.name(i);
    for i in (0..grains.len()).filter(|&i| grains.starts_in_play(i)) {
        for w in walls.iter().filter(|w| w.present) {
            let d = wall_distance(&w.shape, grains.position[i]);
            let allowed = if origins.read(i) { READ_WALL_OVERLAP * grains.radius[i] } else { 0.0 };
            if d < grains.radius[i] - allowed {
                return Err(c.invalid(
                    origin(i),
                    format!("{:?}", grains.position[i]),
                    format!("the grain (radius {:.4e} m) overlaps {} by {:.4e} m", grains.radius[i], w.name, grains.radius[i] - d),
                    "move the grain or its generator's region inside the walls",
                ));
            }
        }
    }
    for i in 0..listed {
        for j in 0..i {
            let d2: f64 = (0..3).map(|k| (grains.position[i][k] - grains.position[j][k]).powi(2)).sum();
            if d2.sqrt() < grains.radius[i] + grains.radius[j] {
                return Err(c.invalid(origin(i), format!("{:?}", grains.position[i]), format!("overlaps grain[{j}]"), "place listed grains apart"));
            }
        }
    }
    Ok(())
}

/// A stage's `walls`: the walls each name moves, with their motion ([`drives_of`]).
pub(super) fn stage_drives(c: &Complainer, stage: usize, specs: &std::collections::BTreeMap<String, schema::WallDriveSpec>, walls: &[Wall], servo: Option<ServoBox>) -> Result<Vec<(usize, WallDrive)>, SceneError> {
    let mut out = Vec::new();
    for (name, d) in specs {
        out.extend(drives_of(c, &format!("stage[{stage}].walls"), name, d.velocity, d.angular_velocity, walls, servo)?);
    }
    Ok(out)
}

/// The walls `name` moves (a plane's or a cylinder's name, or a box's for its faces), each
/// with `velocity` and `angular_velocity` checked as a `[[wall]]`'s; the piston and the servo
/// box's planes, which their controllers move, are refused. `at` is where the name is given
/// (`stage[2].walls`), for errors.
pub(super) fn drives_of(c: &Complainer, at: &str, name: &str, velocity: Option<DVec3>, angular_velocity: Option<DVec3>, walls: &[Wall], servo: Option<ServoBox>) -> Result<Vec<(usize, WallDrive)>, SceneError> {
    let found = walls_named(c, at, name, walls, servo, "set the stage's piston_pressure or servo_pressure instead")?;
    let spin = match walls[found[0]].shape {
        WallShape::Plane { .. } | WallShape::Mesh { .. } if found.len() == 1 => SpinRule::AnyAxis,
        WallShape::Cylinder { .. } => SpinRule::Along(DVec3::Z, "the cylinder's axis (z)"),
        _ => SpinRule::Refused,
    };
    let drive = turning(drive_of(c, &format!("{at}.{name}"), velocity, angular_velocity, spin)?, &walls[found[0]].shape);
    Ok(found.into_iter().map(|k| (k, drive)).collect())
}

/// The fix for adding or removing the piston or a servo plane.
pub(super) const PRESENCE_OF_CONTROLLED: &str = "it stays: its controller holds it on the grains";

/// The walls (indices) that `name` names, given at `at`: a wall's name, or a box's for its
/// faces; the piston and the servo box's planes, which their controllers move, are refused
/// with the fix `controlled`.
pub(super) fn walls_named(c: &Complainer, at: &str, name: &str, walls: &[Wall], servo: Option<ServoBox>, controlled: &str) -> Result<Vec<usize>, SceneError> {
    let found: Vec<usize> = match walls.iter().position(|w| w.name == name) {
        Some(k) => vec![k],
        None => (0..walls.len()).filter(|&k| walls[k].name.strip_prefix(name).is_some_and(|rest| rest.starts_with('.'))).collect(),
    };
    if found.is_empty() {
        let known: Vec<&str> = walls.iter().map(|w| w.name.as_str()).collect();
        let fix = if known.is_empty() { "add a [[wall]] with this name".to_string() } else { format!("use one of {known:?} (a box's name names every face)") };
        return Err(c.invalid(at, format!("\"{name}\""), "names no wall", fix));
    }
    if let Some(&k) = found.iter().find(|&&k| matches!(walls[k].shape, WallShape::Piston { .. }) || servo.is_some_and(|s| s.walls.contains(&k))) {
        return Err(c.invalid(at, format!("\"{name}\""), format!("{} is moved by its controller (the piston or the servo box)", walls[k].name), controlled));
    }
    Ok(found)
}

impl Scene {
    /// The walls `name` moves and their motion, checked as a stage's `walls` are ([`drives_of`];
    /// `at` says where the name comes from, for the error).
    pub fn wall_drives(&self, at: &str, name: &str, velocity: DVec3, angular_velocity: DVec3) -> Result<Vec<(usize, WallDrive)>, SceneError> {
        drives_of(&Complainer { file: &self.path }, at, name, Some(velocity), Some(angular_velocity), &self.walls, self.servo)
    }

    /// The walls `name` names for adding or removing, checked as a stage's `add_walls` and
    /// `remove_walls` are ([`walls_named`]; `at` says where the name comes from).
    pub fn walls_to_add_or_remove(&self, at: &str, name: &str) -> Result<Vec<usize>, SceneError> {
        walls_named(&Complainer { file: &self.path }, at, name, &self.walls, self.servo, PRESENCE_OF_CONTROLLED)
    }
}
