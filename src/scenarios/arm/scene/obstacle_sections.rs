//! The scene around the arm: the `[[obstacles]]` (moved into the robot's base frame),
//! the `[collision]` settings and the `[contact]` scene (table, box, pusher).

use crate::collision::CollisionShape;
use crate::collision::{CollisionOptions, ObstacleSpec};
use crate::core::diag::LocatedError as ScenarioError;
use crate::core::spatial::Se3;
use crate::model::Shape;
use crate::scenarios::arm::scene::arm_scene::ContactScene;
use crate::scenarios::arm::scene::model::link_by_name;
use crate::scenarios::arm::scene::section_reader::{finite_pos, get_f, Sections};

/// The obstacles, each checked and moved into the robot's base frame.
pub(super) fn obstacles(sx: &Sections) -> Result<Vec<ObstacleSpec>, ScenarioError> {
    let cx = &sx.cx;
    let file = sx.file;
    let model = sx.model;
    let base_inv = &sx.base_inv;
    let mut obstacles = Vec::new();
    for (i, o) in file.obstacles.iter().enumerate() {
        let spec = o.get_ref();
        let key = format!("obstacles[{i}] ({})", spec.name);
        let obstacle = spec
            .to_obstacle()
            .map_err(|e| cx.at(o.span(), &key, e.to_string()))?;
        // Primitive dimensions are checked here, with the line (meshes when loaded).
        if !matches!(obstacle.shape, Shape::Mesh { .. }) {
            CollisionShape::primitive(&obstacle.shape)
                .map_err(|e| cx.at(o.span(), &key, e.to_string()))?;
        }
        if model.link_id(&spec.name).is_some() {
            return Err(cx.at(o.span(), &key, "an obstacle may not share a link's name"));
        }
        if obstacles.iter().any(|p: &ObstacleSpec| p.name == spec.name) {
            return Err(cx.at(o.span(), &key, "duplicate obstacle name"));
        }
        let world = Se3::from_xyz_rpy(spec.xyz, spec.rpy);
        let local = base_inv.mul(&world);
        let mut s = spec.clone();
        s.xyz = [local.trans.x, local.trans.y, local.trans.z];
        s.rpy = crate::core::spatial::matrix_to_rpy(&local.rot);
        obstacles.push(s);
    }
    Ok(obstacles)
}

/// The collision settings read from `[collision]`.
pub(super) struct CollisionSection {
    pub planner_disabled: Vec<[String; 2]>,
    pub collision: Option<CollisionOptions>,
    pub self_collision: bool,
}

/// The collision checking options (`touching`: the skeleton's pairs).
pub(super) fn collision(
    sx: &Sections,
    touching: Vec<[String; 2]>,
    obstacles: &[ObstacleSpec],
) -> Result<CollisionSection, ScenarioError> {
    let cx = &sx.cx;
    let file = sx.file;
    let model = sx.model;
    let dir = sx.dir;
    let csec = file.collision.as_ref().map(|c| c.get_ref());
    // The planner leaves these pairs out whether or not the motion is checked.
    let mut planner_disabled = touching.clone();
    if let Some(c) = csec {
        for p in &c.disabled_pairs {
            let [a, b] = p.get_ref().as_slice() else {
                return Err(cx.at(
                    p.span(),
                    "collision.disabled_pairs",
                    format!(
                        "a pair names two links or obstacles, got {}",
                        p.get_ref().len()
                    ),
                ));
            };
            planner_disabled.push([a.clone(), b.clone()]);
        }
    }
    let collision_enabled = csec.is_none_or(|c| c.enabled);
    let self_collision = csec.is_none_or(|c| c.self_collision);
    let collision = if collision_enabled {
        let mut opts = CollisionOptions {
            obstacle_dir: Some(dir.to_path_buf()),
            disabled_pairs: touching,
            ..Default::default()
        };
        if let Some(c) = csec {
            if !(c.margin.is_finite() && c.margin >= 0.0) {
                let sp = file.collision.as_ref().expect("some").span();
                return Err(cx.at(sp, "collision.margin", "must be finite and >= 0"));
            }
            opts.margin = c.margin;
            opts.convex_hulls = c.convex_hulls;
            for p in &c.disabled_pairs {
                for nm in p.get_ref() {
                    if model.link_id(nm).is_none() && !obstacles.iter().any(|o| &o.name == nm) {
                        return Err(cx.at(
                            p.span(),
                            "collision.disabled_pairs",
                            format!("'{nm}' is neither a link nor an obstacle"),
                        ));
                    }
                }
                let pair = p.get_ref();
                opts.disabled_pairs.push([pair[0].clone(), pair[1].clone()]);
            }
        }
        Some(opts)
    } else {
        None
    };
    if let Some(s) = csec.and_then(|c| c.max_step.as_ref()) {
        return Err(cx.at(
            s.span(),
            "collision.max_step",
            "does not apply: the collision check no longer steps through the motion; it \
             certifies the whole timed motion (collisions.certificate in the report), so \
             remove the key",
        ));
    }
    Ok(CollisionSection {
        planner_disabled,
        collision,
        self_collision,
    })
}

/// Largest size or coordinate of the contact scene's table, box and pusher offset (m).
pub const MAX_CONTACT_EXTENT: f64 = 1000.0;

/// The contact scene, when the effect is named.
pub(super) fn contact(
    sx: &Sections,
    named: &[&str],
) -> Result<Option<ContactScene>, ScenarioError> {
    let cx = &sx.cx;
    let file = sx.file;
    let model = sx.model;
    let tool = sx.tool;
    let has = |e: &str| named.contains(&e);
    if !has("contact") {
        return Ok(None);
    }
    {
        let sec = file.contact.as_ref().expect("checked above");
        let c = sec.get_ref();
        let t = c.table.get_ref();
        let b = c.object.get_ref();
        let ok3 = |v: &[f64; 3], pos: bool| {
            v.iter()
                .all(|x| x.is_finite() && x.abs() <= MAX_CONTACT_EXTENT && (!pos || *x > 0.0))
        };
        let table_ok =
            ok3(&t.size, true) && ok3(&t.xyz, false) && t.friction >= 0.0 && t.friction.is_finite();
        if !table_ok {
            return Err(cx.at(
                c.table.span(),
                "contact.table",
                format!(
                    "size must be positive, xyz finite (each within {MAX_CONTACT_EXTENT} m), \
                     friction >= 0"
                ),
            ));
        }
        let box_ok = ok3(&b.size, true)
            && ok3(&b.xyz, false)
            && finite_pos(b.mass)
            && b.friction >= 0.0
            && b.friction.is_finite();
        if !box_ok {
            return Err(cx.at(
                c.object.span(),
                "contact.box",
                format!(
                    "size and mass must be positive, xyz finite (each within \
                     {MAX_CONTACT_EXTENT} m), friction >= 0"
                ),
            ));
        }
        if !ok3(&c.pusher_offset, false) {
            return Err(cx.at(
                sec.span(),
                "contact.pusher_offset",
                format!(
                    "must be finite, each within {MAX_CONTACT_EXTENT} m, got {:?}",
                    c.pusher_offset
                ),
            ));
        }
        let pusher_link = match &c.pusher_link {
            Some(l) => link_by_name(cx, model, l, "contact.pusher_link")?,
            None => tool,
        };
        Ok(Some(ContactScene {
            table_size: t.size,
            table_xyz: t.xyz,
            table_friction: t.friction,
            box_size: b.size,
            box_xyz: b.xyz,
            box_mass: b.mass,
            box_friction: b.friction,
            pusher_link,
            pusher_radius: get_f(cx, &c.pusher_radius, "contact.pusher_radius", 0.03)?,
            pusher_offset: c.pusher_offset,
            dt: get_f(cx, &c.dt, "contact.dt", 0.0)?,
        }))
    }
}
