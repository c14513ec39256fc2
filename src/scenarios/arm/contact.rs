//! The contact scene of an arm scenario (rapier3d-f64), built only when the scenario names
//! the `contact` effect: a fixed table, a dynamic box resting on it under gravity with
//! Coulomb friction, and a kinematic sphere (the pusher) carried by an arm link.
//!
//! Co-simulation, one rapier step per arm step ([`StepHook`]): the pusher is placed at the
//! link pose the arm's forward kinematics gives, rapier steps the box, and the contact
//! impulse `J` between pusher and box gives the force on the box `F = J / h`; its
//! reaction `−F` acts on the arm's link at the sphere centre (the contact normal of a
//! sphere passes through its centre), i.e. the wrench `(−F, (c − o) × (−F))` about the
//! link origin `o`. Only the plant feels it: the controller does not know the contact.
//!
//! [`built_count`] counts the scenes ever built in this process (a left-out effect is
//! never built).

use crate::core::spatial::{Se3, Vec3};
use crate::dynamics::ExternalWrench;
use crate::kinematics::{forward_kinematics, frame_placement};
use crate::model::data::Data;
use crate::model::Model;
use crate::scenarios::arm::scene::ContactScene;
use crate::sim::StepHook;
use rapier3d_f64::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

static BUILT: AtomicUsize = AtomicUsize::new(0);

/// How many contact scenes were built in this process.
pub fn built_count() -> usize {
    BUILT.load(Ordering::Relaxed)
}

/// What happened in the contact scene.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct ContactReport {
    /// Box centre at the start (m).
    pub box_start: [f64; 3],
    /// Box centre at the end (m).
    pub box_end: [f64; 3],
    /// Horizontal distance the box moved (m).
    pub box_displacement_m: f64,
    /// Largest box speed (m/s).
    pub box_max_speed: f64,
    /// Largest pusher–box contact force (N).
    pub max_contact_force_n: f64,
    /// Mean horizontal contact force while the box slides at a steady speed (N), and the
    /// Coulomb value `μ m g` it should match.
    pub sliding_force_n: Option<f64>,
    /// The Coulomb force `μ m g` the sliding force should match (N).
    pub coulomb_force_n: f64,
    /// First contact time (s).
    pub first_contact_s: Option<f64>,
    /// Time in contact (s).
    pub contact_time_s: f64,
    /// rapier steps taken.
    pub steps: usize,
    /// Wall time spent in rapier (s).
    pub wall_time_s: f64,
}

/// The rapier world and the coupling state (a [`StepHook`]).
pub struct ContactSim<'m> {
    world: PhysicsWorld,
    pusher: RigidBodyHandle,
    pusher_c: ColliderHandle,
    object: RigidBodyHandle,
    object_c: ColliderHandle,
    model: &'m Model,
    data: Data,
    base: Se3,
    link: usize,
    offset: Vec3,
    h: f64,
    coulomb: f64,
    /// Samples of (t, box position, box speed, contact force on box).
    pub trace: Vec<(f64, [f64; 3], f64, [f64; 3])>,
    report: ContactReport,
    sliding_sum: f64,
    sliding_n: usize,
    stop: &'m dyn Fn() -> bool,
}

fn v3(a: [f64; 3]) -> Vector {
    Vector::new(a[0], a[1], a[2])
}

impl<'m> ContactSim<'m> {
    /// Builds the scene (`gravity` in scene axes; `h` the arm's step).
    pub fn new(
        model: &'m Model,
        base: Se3,
        scene: &ContactScene,
        gravity: [f64; 3],
        h: f64,
        stop: &'m dyn Fn() -> bool,
    ) -> Self {
        BUILT.fetch_add(1, Ordering::Relaxed);
        let mut world = PhysicsWorld::new();
        world.gravity = v3(gravity);
        world.integration_parameters.dt = h;
        let half = |s: [f64; 3]| (s[0] / 2.0, s[1] / 2.0, s[2] / 2.0);
        let table = world.insert_body(RigidBodyBuilder::fixed().translation(v3(scene.table_xyz)));
        let (hx, hy, hz) = half(scene.table_size);
        world.insert_collider(
            ColliderBuilder::cuboid(hx, hy, hz).friction(scene.table_friction),
            Some(table),
        );
        let (hx, hy, hz) = half(scene.box_size);
        let (object, object_c) = world.insert(
            RigidBodyBuilder::dynamic().translation(v3(scene.box_xyz)),
            ColliderBuilder::cuboid(hx, hy, hz)
                .mass(scene.box_mass)
                .friction(scene.box_friction),
        );
        let (pusher, pusher_c) = world.insert(
            RigidBodyBuilder::kinematic_position_based(),
            ColliderBuilder::ball(scene.pusher_radius).friction(0.0),
        );
        let g = (gravity[0].powi(2) + gravity[1].powi(2) + gravity[2].powi(2)).sqrt();
        // rapier combines two friction coefficients by their average by default.
        let mu = 0.5 * (scene.table_friction + scene.box_friction);
        let mut sim = ContactSim {
            world,
            pusher,
            pusher_c,
            object,
            object_c,
            model,
            data: Data::new(model),
            base,
            link: scene.pusher_link,
            offset: Vec3::new(
                scene.pusher_offset[0],
                scene.pusher_offset[1],
                scene.pusher_offset[2],
            ),
            h,
            coulomb: mu * scene.box_mass * g,
            trace: Vec::new(),
            report: ContactReport {
                box_start: scene.box_xyz,
                coulomb_force_n: mu * scene.box_mass * g,
                ..Default::default()
            },
            sliding_sum: 0.0,
            sliding_n: 0,
            stop,
        };
        sim.report.box_end = scene.box_xyz;
        sim
    }

    /// Pusher centre in scene axes and in base axes at `q`.
    fn pusher_centre(&mut self, q: &[f64]) -> (Vec3, Vec3) {
        forward_kinematics(self.model, &mut self.data, q);
        let link = frame_placement(self.model, &self.data, self.link);
        let c_base = link.act_point(&self.offset);
        (self.base.act_point(&c_base), c_base)
    }

    /// Places the pusher at `q` without stepping (before the first step).
    pub fn place(&mut self, q: &[f64]) {
        let (c, _) = self.pusher_centre(q);
        if let Some(b) = self.world.bodies.get_mut(self.pusher) {
            b.set_translation(Vector::new(c.x, c.y, c.z), true);
        }
    }

    /// The figures so far.
    pub fn report(&self) -> ContactReport {
        let mut r = self.report.clone();
        r.sliding_force_n = (self.sliding_n > 0).then(|| self.sliding_sum / self.sliding_n as f64);
        r
    }
}

impl StepHook for ContactSim<'_> {
    fn before_step(
        &mut self,
        t: f64,
        q: &[f64],
        _qd: &[f64],
        plant: &mut Vec<ExternalWrench>,
    ) -> bool {
        if (self.stop)() {
            return false;
        }
        let start = std::time::Instant::now();
        let (c, c_base) = self.pusher_centre(q);
        if let Some(b) = self.world.bodies.get_mut(self.pusher) {
            b.set_next_kinematic_position(Pose::from_translation(Vector::new(c.x, c.y, c.z)));
        }
        self.world.step();
        // Force on the box from the pusher (the pair's impulse acts on collider 2 along
        // the normal from collider 1).
        let f_box = match self.world.contact_pair(self.pusher_c, self.object_c) {
            Some(pair) if pair.has_any_active_contact() => {
                let j = pair.total_impulse();
                let s = if pair.collider1 == self.pusher_c {
                    1.0
                } else {
                    -1.0
                };
                Vec3::new(j.x, j.y, j.z) * (s / self.h)
            }
            _ => Vec3::zeros(),
        };
        plant.clear();
        let fmag = f_box.norm();
        let obj = &self.world.bodies[self.object];
        let p = obj.translation();
        let v = obj.linvel();
        let speed = (v.x * v.x + v.y * v.y + v.z * v.z).sqrt();
        let r = &mut self.report;
        if fmag > 0.0 {
            // Reaction on the arm, in base axes, about the link origin.
            let f = self.base.rot.transpose() * (-f_box);
            let o = frame_placement(self.model, &self.data, self.link).trans;
            plant.push(ExternalWrench {
                link: self.link,
                force: f,
                moment: (c_base - o).cross(&f),
            });
            r.first_contact_s.get_or_insert(t);
            r.contact_time_s += self.h;
            r.max_contact_force_n = r.max_contact_force_n.max(fmag);
            // Steady sliding: the box moves and its speed barely changes.
            if speed > 1e-3 {
                let prev = self.trace.last().map_or(0.0, |s| s.2);
                if (speed - prev).abs() < 1e-4 {
                    self.sliding_sum += (f_box.x * f_box.x + f_box.y * f_box.y).sqrt();
                    self.sliding_n += 1;
                }
            }
        }
        r.box_max_speed = r.box_max_speed.max(speed);
        r.box_end = [p.x, p.y, p.z];
        let d = [p.x - r.box_start[0], p.y - r.box_start[1]];
        r.box_displacement_m = (d[0] * d[0] + d[1] * d[1]).sqrt();
        r.steps += 1;
        r.wall_time_s += start.elapsed().as_secs_f64();
        self.trace
            .push((t, [p.x, p.y, p.z], speed, [f_box.x, f_box.y, f_box.z]));
        let _ = self.coulomb;
        true
    }

    fn conservative(&self) -> bool {
        false
    }
}
