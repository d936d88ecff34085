// One invocation moves the servo box's six planes by phase.drift (the CPU's servo_drift, in the
// same order): each along its normal at gain x (target - measured pressure), capped at the
// largest speed, the gain lowered to `relaxation` of A / (k tau + c) where the wall's contacts
// respond strongly; in triaxial mode the z planes close at the strain rate instead. The work
// the planes do on the grains is booked (compensated sum).
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<uniform> phase: Phase;
@group(0) @binding(2) var<storage, read_write> walls: array<Wall>;
@group(0) @binding(3) var<storage, read> wall_reaction: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> servo: Servo;

// Wall index of plane k: x_min, x_max, y_min, y_max, z_min, z_max.
fn servo_wall(k: u32) -> u32 {
    if (k < 4u) {
        return servo.walls_lo[k];
    }
    return servo.walls_hi[k - 4u];
}

// Coordinate of plane k along its axis (m).
fn servo_coord(k: u32) -> f32 {
    return walls[servo_wall(k)].point[k / 2u];
}

// The box's extent along each axis (m).
fn servo_extents() -> vec3<f32> {
    return vec3<f32>(servo_coord(1u) - servo_coord(0u), servo_coord(3u) - servo_coord(2u), servo_coord(5u) - servo_coord(4u));
}

// x.y, summed as the CPU's Vec3::dot does.
fn dot_in_order(x: vec3<f32>, y: vec3<f32>) -> f32 {
    return x.x * y.x + x.y * y.y + x.z * y.z;
}

// Pressure the grains exert on plane k (Pa), over the box's current cross-section.
fn servo_pressure(k: u32) -> f32 {
    let e = servo_extents();
    let a = k / 2u;
    let area = e[(a + 1u) % 3u] * e[(a + 2u) % 3u];
    let w = servo_wall(k);
    return -dot_in_order(wall_reaction[w].xyz, walls[w].normal.xyz) / area;
}

// Adds x to the booked work (J), keeping the rounding error in work_lo.
fn book_work(x: f32) {
    let s = servo.work + x;
    let back = s - servo.work;
    let err = (servo.work - (s - back)) + (x - back);
    servo.work = s;
    servo.work_lo += err;
}

@compute @workgroup_size(1)
fn servo_move() {
    let e0 = servo_extents();
    for (var k = 0u; k < 6u; k++) {
        let w = servo_wall(k);
        let a = k / 2u;
        let area = e0[(a + 1u) % 3u] * e0[(a + 2u) % 3u];
        let response = wall_reaction[MAX_WALLS + w].x * phase.drift + wall_reaction[MAX_WALLS + w].y;
        var gain = servo.gain;
        if (response > 0.0) {
            gain = min(servo.gain, servo.relaxation * area / response);
        }
        var speed: f32;
        if (servo.strain != 0u && k >= 4u) {
            speed = servo.strain_rate * e0.z * 0.5;
        } else {
            speed = min(max(gain * (servo.pressure - servo_pressure(k)), -servo.max_speed), servo.max_speed);
        }
        let n = walls[w].normal.xyz;
        let v = n * speed;
        walls[w].point = vec4<f32>(walls[w].point.xyz + v * phase.drift, walls[w].point.w);
        walls[w].velocity = vec4<f32>(v, 0.0);
        book_work(-(dot_in_order(wall_reaction[w].xyz, v) * phase.drift));
    }
}
