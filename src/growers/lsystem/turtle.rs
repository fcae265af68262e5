//! The 3D turtle of *The Algorithmic Beauty of Plants* (Prusinkiewicz & Lindenmayer 1990,
//! ch. 1.5): a position and the frame H (heading), L (left), U (up), H x L = U.
//!
//! Sign conventions, pinned by a golden test because tools disagree: every positive turn is
//! right-handed about its axis, so `+` turns H toward L (counter-clockwise seen from U, as
//! ABOP's 2D turtle: "+ turn left"), `&` pitches H toward -U ("pitch down"), `\` rolls L
//! toward U ("roll left"). The turtle starts at the origin heading up (H = +z) with
//! L = -x and U = -y, so a 2D system draws in the x-z plane seen from the south (-y): x to
//! the right, z up, `+` counter-clockwise on the page.
//!
//! | symbol | meaning |
//! |---|---|
//! | `F`, `F(l)` | draw forward `step` (or `l`) metres: a branch segment |
//! | `f`, `f(l)` | move forward without drawing |
//! | `+ -`, `+(a)` | yaw left / right by `angle` (or `a`) degrees, about U |
//! | `& ^` | pitch down / up, about L |
//! | `\ /` | roll left / right, about H |
//! | `\|` | turn around (yaw 180 degrees) |
//! | `$` | roll until L is horizontal |
//! | `[ ]` | push / pop the state |
//! | `!`, `!(w)` | multiply the width by `width_decay` (or set it to `w`) |
//! | `'`, `'(n)` | next material index (or set it to `n`) |
//! | `{ . }` | a leaf polygon: `.` records a corner; `F`/`f` inside only move |
//! | `@` | mark a dot (e.g. a seed of a phyllotaxis disc) |
//!
//! Any other symbol draws nothing and stays in the string. After every `F` the heading bends
//! toward the tropism vector T by `elasticity * |H x T|` radians (ABOP eq. 2.4).

use super::grammar::Word;
use crate::growers::skeleton::{Node, Polygon, Skeleton};
use crate::growers::v3::{self, V3};

/// What the symbols mean in numbers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TurtleParams {
    /// Length of `F` and `f` without a parameter, metres.
    pub step: f64,
    /// Turning angle of `+ - & ^ \ /` without a parameter, degrees.
    pub angle: f64,
    /// Starting width (diameter) of a branch, metres.
    pub width: f64,
    /// What `!` multiplies the width by.
    pub width_decay: f64,
    /// The tropism vector T (e.g. gravity [0, 0, -1]).
    pub tropism: V3,
    /// How strongly branches bend toward T; 0 for none.
    pub elasticity: f64,
}

impl Default for TurtleParams {
    fn default() -> TurtleParams {
        TurtleParams {
            step: 1.0,
            angle: 90.0,
            width: 0.1,
            width_decay: 0.7,
            tropism: [0.0, 0.0, -1.0],
            elasticity: 0.0,
        }
    }
}

#[derive(Debug, Clone, Copy)]
struct State {
    at: V3,
    h: V3,
    l: V3,
    u: V3,
    width: f64,
    material: u8,
    /// The node the next `F` grows from; `None` after a move.
    node: Option<u32>,
}

/// The turtle's reading of `word`: its branches as a skeleton, leaf polygons and dots.
pub fn interpret(word: &Word, p: &TurtleParams) -> Skeleton {
    let mut sk = Skeleton::default();
    let mut s = State {
        at: [0.0; 3],
        h: [0.0, 0.0, 1.0],
        l: [-1.0, 0.0, 0.0],
        u: [0.0, -1.0, 0.0],
        width: p.width,
        material: 0,
        node: None,
    };
    let mut stack: Vec<State> = Vec::new();
    let mut polygon: Option<Vec<V3>> = None;
    let mut polygons_open: Vec<Option<Vec<V3>>> = Vec::new();
    let deg = p.angle.to_radians();
    for m in &word.modules {
        let arg = word.args_of(m).first().copied();
        let angle = arg.map_or(deg, f64::to_radians);
        match m.sym {
            b'F' | b'f' => {
                let len = arg.unwrap_or(p.step);
                let to = v3::add(s.at, v3::scale(s.h, len));
                if m.sym == b'F' && polygon.is_none() {
                    let from = match s.node {
                        Some(n) => n,
                        None => {
                            sk.nodes.push(Node {
                                at: s.at,
                                parent: None,
                                radius: s.width / 2.0,
                                material: s.material,
                            });
                            (sk.nodes.len() - 1) as u32
                        }
                    };
                    sk.nodes.push(Node {
                        at: to,
                        parent: Some(from),
                        radius: s.width / 2.0,
                        material: s.material,
                    });
                    s.node = Some((sk.nodes.len() - 1) as u32);
                    s.at = to;
                    bend(&mut s, p);
                } else {
                    s.at = to;
                    if polygon.is_none() {
                        s.node = None;
                    }
                }
            }
            b'+' => yaw(&mut s, angle),
            b'-' => yaw(&mut s, -angle),
            b'|' => yaw(&mut s, std::f64::consts::PI),
            b'&' => pitch(&mut s, angle),
            b'^' => pitch(&mut s, -angle),
            b'\\' => roll(&mut s, angle),
            b'/' => roll(&mut s, -angle),
            b'$' => {
                if let Some(l) = v3::unit(v3::cross([0.0, 0.0, 1.0], s.h)) {
                    s.l = l;
                    s.u = v3::cross(s.h, l);
                }
            }
            b'[' => {
                stack.push(s);
                polygons_open.push(polygon.take());
            }
            b']' => {
                if let Some(old) = stack.pop() {
                    s = old;
                    polygon = polygons_open.pop().flatten();
                }
            }
            b'!' => s.width = arg.unwrap_or(s.width * p.width_decay),
            b'\'' => {
                s.material = match arg {
                    Some(n) => n.clamp(0.0, 255.0) as u8,
                    None => s.material.saturating_add(1),
                }
            }
            b'{' => polygon = Some(Vec::new()),
            b'.' => {
                if let Some(poly) = polygon.as_mut() {
                    poly.push(s.at);
                }
            }
            b'}' => {
                if let Some(corners) = polygon.take() {
                    if corners.len() >= 3 {
                        sk.polygons.push(Polygon {
                            corners,
                            material: s.material,
                        });
                    }
                }
            }
            b'@' => sk.dots.push(s.at),
            _ => {}
        }
    }
    sk
}

fn yaw(s: &mut State, a: f64) {
    s.h = v3::rotate(s.h, s.u, a);
    s.l = v3::rotate(s.l, s.u, a);
}

fn pitch(s: &mut State, a: f64) {
    s.h = v3::rotate(s.h, s.l, a);
    s.u = v3::rotate(s.u, s.l, a);
}

fn roll(s: &mut State, a: f64) {
    s.l = v3::rotate(s.l, s.h, a);
    s.u = v3::rotate(s.u, s.h, a);
}

/// Tropism: turn the frame about H x T by `elasticity * |H x T|`, bending H toward T.
fn bend(s: &mut State, p: &TurtleParams) {
    if p.elasticity == 0.0 {
        return;
    }
    let axis = v3::cross(s.h, p.tropism);
    let Some(k) = v3::unit(axis) else {
        return;
    };
    let a = p.elasticity * v3::norm(axis);
    s.h = v3::rotate(s.h, k, a);
    s.l = v3::rotate(s.l, k, a);
    s.u = v3::rotate(s.u, k, a);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::growers::lsystem::grammar::parse_axiom;

    fn end_of(word: &str, angle: f64) -> V3 {
        let sk = interpret(
            &parse_axiom(word).unwrap(),
            &TurtleParams {
                angle,
                ..TurtleParams::default()
            },
        );
        sk.nodes.last().unwrap().at
    }

    fn close(a: V3, b: V3) -> bool {
        v3::dist(a, b) < 1e-9
    }

    /// The golden test of the sign conventions (see the module's doc).
    #[test]
    fn the_sign_conventions_are_abops() {
        assert!(close(end_of("F", 90.0), [0.0, 0.0, 1.0]));
        // + turns left: counter-clockwise seen from the south, toward -x.
        assert!(close(end_of("+F", 90.0), [-1.0, 0.0, 0.0]));
        assert!(close(end_of("-F", 90.0), [1.0, 0.0, 0.0]));
        // & pitches down, toward -U = +y (north, away from the viewer).
        assert!(close(end_of("&F", 90.0), [0.0, 1.0, 0.0]));
        assert!(close(end_of("^F", 90.0), [0.0, -1.0, 0.0]));
        // \ rolls left: after a roll of 90 degrees, + turns toward where U was.
        assert!(close(end_of("\\+F", 90.0), [0.0, -1.0, 0.0]));
        assert!(close(end_of("/+F", 90.0), [0.0, 1.0, 0.0]));
        assert!(close(end_of("|F", 90.0), [0.0, 0.0, -1.0]));
    }

    #[test]
    fn branches_return_to_their_fork_and_widths_decay() {
        let sk = interpret(&parse_axiom("F[+F!F]F").unwrap(), &TurtleParams::default());
        // root, F, +F, !F, F: the last F grows from the first F's end.
        assert_eq!(sk.nodes.len(), 5);
        assert_eq!(sk.nodes[4].parent, Some(1));
        assert!((sk.nodes[3].radius - 0.035).abs() < 1e-12);
        assert_eq!(sk.tips(), vec![3, 4]);
    }

    #[test]
    fn a_polygon_records_its_corners_and_draws_no_branch() {
        let sk = interpret(
            &parse_axiom("F[{.-f.+f.}]").unwrap(),
            &TurtleParams::default(),
        );
        assert_eq!(sk.nodes.len(), 2);
        assert_eq!(sk.polygons.len(), 1);
        assert_eq!(sk.polygons[0].corners.len(), 3);
    }

    #[test]
    fn gravity_tropism_bends_a_horizontal_branch_down() {
        let sk = interpret(
            &parse_axiom("+FFFF").unwrap(),
            &TurtleParams {
                elasticity: 0.3,
                ..TurtleParams::default()
            },
        );
        assert!(sk.nodes.last().unwrap().at[2] < -0.5);
    }
}
