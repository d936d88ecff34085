//! Walls that stages add and remove (`add_walls`, `remove_walls`): which walls are there at
//! the start, and what each stage changes, checked in stage order.

use super::wall_specs::{walls_named, PRESENCE_OF_CONTROLLED};
use super::*;

/// Each wall's presence at the start (a wall that a stage adds before any removes it starts
/// away) and each stage's changes, `(wall, present)`, in stage order. A wall added while it
/// is there, removed while it is away, or named twice in one stage is refused, as are the
/// piston and the servo box's planes.
pub(super) fn wall_presence(c: &Complainer, specs: &[StageSpec], walls: &[Wall], servo: Option<ServoBox>) -> Result<(Vec<bool>, Vec<Vec<(usize, bool)>>), SceneError> {
    let mut present = vec![true; walls.len()];
    // Each wall's presence after the last change, and the key that changed it.
    let mut last: Vec<Option<(bool, String)>> = vec![None; walls.len()];
    let mut out = Vec::with_capacity(specs.len());
    for (i, s) in specs.iter().enumerate() {
        let mut changes: Vec<(usize, bool)> = Vec::new();
        for (key, names, adds) in [("add_walls", &s.add_walls, true), ("remove_walls", &s.remove_walls, false)] {
            for (k, name) in names.iter().enumerate() {
                let at = format!("stage[{i}].{key}[{k}]");
                for w in walls_named(c, &at, name, walls, servo, PRESENCE_OF_CONTROLLED)? {
                    if changes.iter().any(|&(x, _)| x == w) {
                        return Err(c.invalid(&at, format!("\"{name}\""), format!("{} is added or removed twice in this stage", walls[w].name), "name each wall once per stage"));
                    }
                    match &last[w] {
                        Some((now, by)) if *now == adds => {
                            let state = if adds { "there already" } else { "away already" };
                            return Err(c.invalid(&at, format!("\"{name}\""), format!("{} is {state} ({by})", walls[w].name), format!("leave it out of `{key}` here")));
                        }
                        None => present[w] = !adds,
                        Some(_) => {}
                    }
                    last[w] = Some((adds, at.clone()));
                    changes.push((w, adds));
                }
            }
        }
        out.push(changes);
    }
    Ok((present, out))
}
