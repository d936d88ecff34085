// Contact dynamics' sweeps (src/cd/solve.rs, src/gpu/sweeps.rs): the structures and a
// contact's exact local problem. Every dot and cross product is written out in the order the
// CPU twin adds in (Vec3::dot, Vec3::cross), so that f32 gives its bits where the device
// neither fuses nor reorders (lavapipe fuses a multiply and an add now and then). Keep the
// structures in sync with src/gpu/layout.rs.

// Contacts per block of the convergence measure's sum (src/cd/solve.rs MEASURE_BLOCK).
const MEASURE_BLOCK: u32 = 256u;

// A contact of the step (src/cd/mod.rs Contact).
struct CdContact {
    a: u32,             // first body: a grain
    b: u32,             // second body: a grain, or a wall's index when to_wall is 1
    to_wall: u32,
    _pad0: u32,
    n: vec4<f32>,       // xyz: unit normal from a to b; w: u_min, the least normal velocity at the step's end (m/s)
    radius_a: f32,      // m
    radius_b: f32,      // m (0 for a wall)
    mu: f32,            // friction coefficient
    w_n: f32,           // normal Delassus diagonal (1/kg)
    w_t: f32,           // tangential Delassus diagonal (1/kg)
    inv_mass_a: f32,    // 1/kg
    inv_inertia_a: f32, // 1/(kg m^2)
    inv_mass_b: f32,    // 1/kg (a wall's along its normal; 0 for a wall that does not yield)
    inv_inertia_b: f32, // 1/(kg m^2)
    inv_w_n: f32,       // 1 / w_n (kg)
    inv_w_t: f32,       // 1 / w_t (kg)
    _pad1: f32,
}

// The solve's constants (uniform).
struct CdParams {
    n_contacts: u32,
    tail: u32,           // first contact of the serial tail (walls, uncoloured pairs)
    n_blocks: u32,       // blocks of the convergence measure
    max_iterations: u32, // sweeps at most
    tolerance2: f32,     // square of the quadratic norm at which the sweeps stop (-)
    relaxation: f32,     // over-relaxation factor (-; 1: plain Gauss-Seidel)
    _pad1: f32,
    _pad2: f32,
}

// A colour: contacts start..end (uniform, dynamic offset).
struct CdColour {
    start: u32,
    end: u32,
    _pad0: u32,
    _pad1: u32,
}

// Where the sweeps stand; every kernel does nothing once done is set.
struct CdControl {
    iterations: u32,      // sweeps run
    converged: u32,       // 1: the sweeps' quadratic norm fell to the tolerance
    done: u32,            // 1: converged or at the cap
    _pad0: u32,
    sweep_norm2: f32,     // square of the last sweep's quadratic norm (-)
    _pad1: f32,
    _pad2: f32,
    _pad3: f32,
}

// A body's motion as the local problem sees it (m/s, rad/s).
struct Motion {
    vel: vec3<f32>,
    omega: vec3<f32>,
}

// A solved contact: its new impulse (N s, on b), both bodies' motions with the change applied,
// and its share of the convergence measure (|W dr|^2, |W r|^2): the squared velocity correction
// its solve made and the squared velocity its impulse gives it.
struct Solved {
    r: vec3<f32>,
    a: Motion,
    b: Motion,
    measure: vec2<f32>,
}

fn dot3(p: vec3<f32>, q: vec3<f32>) -> f32 {
    return p.x * q.x + p.y * q.y + p.z * q.z;
}

fn cross3(p: vec3<f32>, q: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(p.y * q.z - p.z * q.y, p.z * q.x - p.x * q.z, p.x * q.y - p.y * q.x);
}

fn norm3(p: vec3<f32>) -> f32 {
    return sqrt(dot3(p, p));
}

// |W v|^2 ((m/s)^2): the squared velocity an impulse v (N s) gives contact c through its local
// Delassus diagonal, (w_n v_n)^2 + w_t^2 |v_t|^2.
fn weighted2(c: CdContact, v: vec3<f32>) -> f32 {
    let n = c.n.xyz;
    let v_n = dot3(v, n);
    let normal = c.w_n * v_n;
    let tangential = (v - n * v_n) * c.w_t;
    return normal * normal + dot3(tangential, tangential);
}

// Velocity of b against a at the contact point (m/s).
fn relative_velocity(c: CdContact, a: Motion, b: Motion) -> vec3<f32> {
    let n = c.n.xyz;
    return (b.vel + cross3(b.omega, n * -c.radius_b)) - (a.vel + cross3(a.omega, n * c.radius_a));
}

// Normal velocity of b against a at the contact (m/s): spin moves no contact point along n.
fn normal_velocity(c: CdContact, a: Motion, b: Motion) -> f32 {
    return dot3(b.vel - a.vel, c.n.xyz);
}

// Whether the contact carries no impulse and its bodies' normal velocity is at least u_min:
// its local solution is then no impulse, and solving it changes nothing.
fn stays_open(c: CdContact, r_old: vec3<f32>, a: Motion, b: Motion) -> bool {
    return all(r_old == vec3<f32>(0.0)) && normal_velocity(c, a, b) >= c.n.w;
}

// The contact's impulse solving its local problem exactly (Signorini with u_min, Coulomb),
// against the others' impulses, which the motions hold with its own r_old.
fn local_impulse(c: CdContact, r_old: vec3<f32>, a: Motion, b: Motion) -> vec3<f32> {
    let n = c.n.xyz;
    let own_n = dot3(r_old, n);
    let u_n = normal_velocity(c, a, b) - c.w_n * own_n;
    let own_t = r_old - n * own_n;
    let u_other = relative_velocity(c, a, b) - n * (c.w_n * own_n) - own_t * c.w_t;
    let r_n = max((c.n.w - u_n) * c.inv_w_n, 0.0);
    let u_t = u_other - n * u_n;
    let stick = u_t * -c.inv_w_t;
    let cap = c.mu * r_n;
    var r_t = stick;
    if (!(dot3(stick, stick) <= cap * cap)) {
        let s = norm3(u_t);
        r_t = vec3<f32>(0.0);
        if (s > 0.0) {
            r_t = u_t * (-cap / s);
        }
    }
    return n * r_n + r_t;
}

// The impulse a sweep leaves at contact c from its local solution star: star itself when omega
// is 1, else over-relaxed from r_old, r_old + omega (star - r_old), and put back in the
// admissible set (r_n >= 0, the tangential part clipped to the cone mu r_n along itself).
fn relax(c: CdContact, r_old: vec3<f32>, star: vec3<f32>, omega: f32) -> vec3<f32> {
    if (omega == 1.0) {
        return star;
    }
    let n = c.n.xyz;
    let x = r_old + (star - r_old) * omega;
    let x_n = dot3(x, n);
    let r_n = max(x_n, 0.0);
    var r_t = x - n * x_n;
    let cap = c.mu * r_n;
    let norm2 = dot3(r_t, r_t);
    if (!(norm2 <= cap * cap)) {
        r_t = r_t * (cap / sqrt(norm2));
    }
    return n * r_n + r_t;
}

// Solves contact c between a and b and applies the change of its impulse to both; a wall (b)
// moves along the normal only.
fn solve_contact(c: CdContact, r_old: vec3<f32>, a: Motion, b: Motion, omega: f32) -> Solved {
    var out: Solved;
    out.r = r_old;
    out.a = a;
    out.b = b;
    out.measure = vec2<f32>(0.0);
    if (stays_open(c, r_old, a, b)) {
        return out;
    }
    let n = c.n.xyz;
    let star = local_impulse(c, r_old, a, b);
    let r = relax(c, r_old, star, omega);
    let dr = r - r_old;
    out.r = r;
    out.measure = vec2<f32>(weighted2(c, star - r_old), weighted2(c, r));
    // A change of exactly zero is not applied, as on the CPU.
    if (all(dr == vec3<f32>(0.0))) {
        return out;
    }
    out.a = Motion(a.vel - dr * c.inv_mass_a, a.omega - cross3(n * c.radius_a, dr) * c.inv_inertia_a);
    if (c.to_wall != 0u) {
        out.b = Motion(b.vel + n * (dot3(n, dr) * c.inv_mass_b), b.omega);
    } else {
        out.b = Motion(b.vel + dr * c.inv_mass_b, b.omega + cross3(n * -c.radius_b, dr) * c.inv_inertia_b);
    }
    return out;
}
