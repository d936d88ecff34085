//! Contact-dynamics scenes the tests share.

use grains::scene::Scene;

/// `count` glass spheres (diameters 0.8 to 1.2 mm) thrown at 0.2 m/s into a closed box of
/// `size` (m) and falling: thousands of contacts per step, sticking and sliding, on the walls
/// too. Contact dynamics at dt = 50 us, tolerance 1e-4 within 200 sweeps; the wide gap
/// allowance (0.3 mm) lists open contacts too, so that the colours are large.
pub fn falling_box(count: usize, size: [f64; 3]) -> Scene {
    let [x, y, z] = size;
    super::parse(&format!(
        r#"
seed = 3
[[material]]
name = "glass"
density = 2500.0
youngs_modulus = 7.0e10
poisson_ratio = 0.25
mu_s = 0.4
restitution = 0.5

[[generate]]
material = "glass"
count = {count}
diameter = {{ min = 0.8e-3, max = 1.2e-3 }}
region = {{ shape = "box", min = [0.0, 0.0, 0.0], max = [{x:e}, {y:e}, {z:e}] }}
random_speed = 0.2

[[wall]]
type = "box"
material = "glass"
min = [0.0, 0.0, 0.0]
max = [{x:e}, {y:e}, {z:e}]

[simulation]
method = "contact_dynamics"
gravity = [0.0, 0.0, -9.81]
dt = 5.0e-5

[contact_dynamics]
tolerance = 1.0e-4
max_iterations = 200
gap_allowance = 3.0e-4

[[stage]]
kind = "run"
duration = 1.0e-2
"#
    ))
}

/// 600 glass spheres (0.7 to 1.4 mm) in a 12 mm servo box pressing at 100 Pa, no gravity:
/// the six walls are bodies of contact dynamics (dt = 100 us, tolerance 1e-4 within 200
/// sweeps).
pub fn servo_box() -> Scene {
    super::parse(
        r#"
seed = 11
[[material]]
name = "glass"
density = 2500.0
youngs_modulus = 7.0e10
poisson_ratio = 0.25
mu_s = 0.4
restitution = 0.3

[[generate]]
material = "glass"
count = 600
diameter = { min = 0.7e-3, max = 1.4e-3 }
region = { shape = "box", min = [0.0, 0.0, 0.0], max = [12.0e-3, 12.0e-3, 12.0e-3] }

[[wall]]
type = "servo_box"
material = "glass"
min = [0.0, 0.0, 0.0]
max = [12.0e-3, 12.0e-3, 12.0e-3]
pressure = 100.0
max_speed = 0.05

[simulation]
method = "contact_dynamics"
gravity = [0.0, 0.0, 0.0]
dt = 1.0e-4

[contact_dynamics]
tolerance = 1.0e-4
max_iterations = 200

[[stage]]
kind = "run"
duration = 0.02
"#,
    )
}
