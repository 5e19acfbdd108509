//! The Rust back end of spatial plans: a [`Plan`] becomes a module of the
//! same shape as a planar one — named constants for bodies and markers, a
//! `State` of fixed-size arrays, `solve` as straight-line code and a `Plan`
//! implementing `dofplan_runtime::Solver` (with `Pose = Pose3`).
//!
//! Every step becomes one block under a comment holding its explanation,
//! calling exactly the runtime function the interpreter
//! ([`crate::interp::spatial`]) calls for it, on the points and directions
//! it reads bound to named locals. The frame runs on a copy of the (`Copy`)
//! state that is written back only when every step succeeded, so a break
//! leaves the state as it was. A numeric cluster becomes a fixed-size
//! closure (see [`super::spatial_cluster`]).
//!
//! Unlike a planar module, the state itself is the working set: poses,
//! pseudo-markers and branch slots are read and written in place in the
//! copy. So a large plan splits into functions of bounded size that take
//! the copy by reference, with nothing to hand from one to the next.

use std::cell::{Cell, RefCell};
use std::collections::{HashMap, HashSet};

use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::{format_ident, quote};

use dofplan_runtime::spatial::rows::RowKind;
use dofplan_runtime::spatial::Vec3;
use dofplan_runtime::Branch;

use super::chunk::CHUNK_WEIGHT;
use super::uses::Uses;
use super::{ident_for, index, lit, names};
use crate::model::InputKind;
use crate::plan::spatial::{Action, CheckRow, DirRef, HingeTurn, Locus, Plan, PointRef, StepKind};

/// A point or direction as a literal `[x, y, z]`.
pub(super) fn vec_lit(v: Vec3) -> TokenStream {
    let (x, y, z) = (lit(v[0]), lit(v[1]), lit(v[2]));
    quote!([#x, #y, #z])
}

/// A primitive's rows as a constant expression (`RowKind::OffsetZ { cos: 0.5 }`).
pub(super) fn row_kind(k: &RowKind) -> TokenStream {
    match *k {
        RowKind::Coincident => quote!(RowKind::Coincident),
        RowKind::InLine => quote!(RowKind::InLine),
        RowKind::InPlane => quote!(RowKind::InPlane),
        RowKind::ParallelZ => quote!(RowKind::ParallelZ),
        RowKind::OffsetZ { cos } => {
            let cos = lit(cos);
            quote!(RowKind::OffsetZ { cos: #cos })
        }
        RowKind::OffsetX { angle } => {
            let angle = lit(angle);
            quote!(RowKind::OffsetX { angle: #angle })
        }
        RowKind::Helical { angle, pitch, axial0 } => {
            let (angle, pitch, axial0) = (lit(angle), lit(pitch), lit(axial0));
            quote!(RowKind::Helical { angle: #angle, pitch: #pitch, axial0: #axial0 })
        }
        RowKind::Angle { angle, input } => {
            let (angle, input) = (lit(angle), index(input));
            quote!(RowKind::Angle { angle: #angle, input: #input })
        }
        RowKind::Slide { axial0, input } => {
            let (axial0, input) = (lit(axial0), index(input));
            quote!(RowKind::Slide { axial0: #axial0, input: #input })
        }
    }
}

/// Names no local of a step may take: the frame's own (the working copy,
/// the parameters) and the runtime's modules.
const RESERVED: [&str; 14] = [
    "w",
    "s",
    "ctx",
    "inputs",
    "input_values",
    "spatial",
    "cluster",
    "numeric",
    "root",
    "gap",
    "sin",
    "cos",
    "turn",
    "Jet2",
];

/// The locals of one step's block: each point and direction the step reads
/// is bound once, under the marker's name or the role it plays, so the
/// runtime call below reads like the step's explanation.
pub(super) struct Block<'p> {
    plan: &'p Plan,
    /// Whether the step is written for `solve_rates`: on jets, every
    /// constant point, direction and input expression lifted to
    /// [`Jet2`](dofplan_runtime::real::Jet2)s.
    pub jets: bool,
    /// The bindings, in order.
    pub pre: Vec<TokenStream>,
    taken: HashSet<String>,
    /// Each bound expression (as text) and its local, so a point read twice
    /// is computed once.
    bound: HashMap<String, Ident>,
}

impl<'p> Block<'p> {
    /// An empty block of a step of `plan`.
    pub fn new(plan: &'p Plan) -> Block<'p> {
        Block {
            plan,
            jets: false,
            pre: Vec::new(),
            taken: RESERVED.iter().map(|s| s.to_string()).collect(),
            bound: HashMap::new(),
        }
    }

    /// A constant point or direction: a literal, or lifted to jets.
    pub fn vlit(&self, v: Vec3) -> TokenStream {
        let l = vec_lit(v);
        if self.jets {
            quote!(spatial::cst(#l))
        } else {
            l
        }
    }

    /// A constant number: a literal, or lifted to a jet.
    pub fn slit(&self, x: f64) -> TokenStream {
        let l = lit(x);
        if self.jets {
            quote!(Jet2::cst(#l))
        } else {
            quote!(#l)
        }
    }

    /// A local name from `base` that no other local of the block has.
    pub fn fresh(&mut self, base: &str) -> Ident {
        let mut name = base.to_string();
        let mut n = 2;
        while !self.taken.insert(name.clone()) {
            name = format!("{base}_{n}");
            n += 1;
        }
        Ident::new(&name, Span::call_site())
    }

    /// Binds `expr` to a local named from `base` (or finds the local that
    /// already holds it).
    pub fn bind(&mut self, base: &str, expr: TokenStream) -> TokenStream {
        let key = expr.to_string();
        if let Some(id) = self.bound.get(&key) {
            return quote!(#id);
        }
        let id = self.fresh(base);
        self.pre.push(quote!(let #id = #expr;));
        self.bound.insert(key, id.clone());
        quote!(#id)
    }

    /// The local name of the point `local` of `body`: its marker's
    /// ("coupler.B" → `coupler_b`), or the body's.
    fn point_name(&self, body: usize, local: Vec3) -> String {
        let marker = self
            .plan
            .markers
            .get(body)
            .and_then(|ms| ms.iter().find(|(_, at)| *at == local));
        match marker {
            Some((m, _)) => ident_for(&format!("{}.{m}", self.plan.bodies[body])),
            None => format!("{}_point", ident_for(&self.plan.bodies[body])),
        }
    }

    /// A point as an expression of `pose(body)` (the state's poses, or a
    /// cluster's trial poses), and the name it is bound under.
    pub fn point_expr(
        &self,
        p: &PointRef,
        pose: &dyn Fn(usize) -> TokenStream,
    ) -> Option<(String, TokenStream)> {
        match p {
            PointRef::Fixed(_) => None,
            PointRef::Body { body, local } => {
                let (b, l) = (pose(*body), vec_lit(*local));
                Some((self.point_name(*body, *local), quote!(#b.world(#l))))
            }
            PointRef::Slid {
                body,
                local,
                dir,
                input,
                sign,
            } => {
                let (b, l, d) = (pose(*body), vec_lit(*local), vec_lit(*dir));
                let i = index(*input);
                // ±1 exactly as the interpreter's `sign * s`: multiplying by
                // ±1 is exact, so the negation is the same number.
                let s = if *sign == 1.0 {
                    quote!(inputs[#i])
                } else if *sign == -1.0 {
                    quote!(-inputs[#i])
                } else if self.jets {
                    let k = lit(*sign);
                    quote!(inputs[#i].mul_f64(#k))
                } else {
                    let k = lit(*sign);
                    quote!(#k * inputs[#i])
                };
                // Another body's marker carried along the slide (a rod's end
                // seen from its barrel): named for the body it rides on.
                let name = format!("{}_slid", ident_for(&self.plan.bodies[*body]));
                if self.jets {
                    return Some((
                        name,
                        quote!(#b.world_of(spatial::add(spatial::cst(#l), spatial::scale(spatial::cst(#d), #s)))),
                    ));
                }
                Some((name, quote!(#b.world(spatial::add(#l, spatial::scale(#d, #s))))))
            }
            PointRef::Temp(t) => {
                let t_lit = index(*t);
                Some((
                    format!("at_{}", ident_for(&self.plan.temps[*t].name)),
                    quote!(w.temps[#t_lit]),
                ))
            }
        }
    }

    /// A world point the step reads, at the state's poses: a literal, or a
    /// local bound in the block.
    pub fn point(&mut self, p: &PointRef) -> TokenStream {
        match p {
            PointRef::Fixed(v) => self.vlit(*v),
            _ => {
                let (name, expr) = self.point_expr(p, &state_pose).expect("not fixed");
                self.bind(&name, expr)
            }
        }
    }

    /// A world direction the step reads, bound under `role` unless constant.
    pub fn dir(&mut self, d: &DirRef, role: &str) -> TokenStream {
        match d {
            DirRef::Fixed(v) => self.vlit(*v),
            DirRef::Body { body, local } => {
                let (b, l) = (state_pose(*body), vec_lit(*local));
                self.bind(role, quote!(#b.dir(#l)))
            }
            DirRef::Between(a, b) => {
                let (a, b) = (self.point(a), self.point(b));
                self.bind(role, quote!(spatial::unit(spatial::sub(#b, #a))))
            }
            DirRef::Temp(t) => {
                let t = index(*t);
                quote!(w.temps[#t])
            }
        }
    }
}

/// Why `solve` works on a copy, as its comment says.
const COPY: &str = "Keep a copy to restore on a break (an early return) and work on `s` itself: a break leaves `s` as it was, no caller has to copy the state per frame to roll back, and a frame copies the state once.";

/// A body's pose in the frame's working copy.
pub(super) fn state_pose(body: usize) -> TokenStream {
    let b = index(body);
    quote!(w.poses[#b])
}

/// Writes one spatial plan's module.
pub(super) struct Emitter3<'p> {
    /// The plan.
    pub plan: &'p Plan,
    /// Comments inside a step (a cluster's rows), by the index their
    /// placeholder names.
    pub notes: RefCell<Vec<String>>,
    /// Whether steps are written for `solve_rates` (on jets).
    pub jets: Cell<bool>,
}

impl Emitter3<'_> {
    /// A placeholder statement that becomes the comment `// text`.
    pub fn note(&self, text: String) -> TokenStream {
        let mut notes = self.notes.borrow_mut();
        let i = index(notes.len());
        notes.push(text);
        quote!(__dofplan_note!(#i);)
    }

    fn step(&self, i: usize) -> TokenStream {
        let step = &self.plan.steps[i];
        // Step ids are 1-based, as the interpreter reports them and
        // `dofplan plan` numbers them.
        let id = Literal::u32_unsuffixed((i + 1) as u32);
        let marker_i = index(i);
        let marker = quote!(__dofplan_step!(#marker_i););
        let mut b = Block::new(self.plan);
        b.jets = self.jets.get();
        let code = match &step.kind {
            StepKind::Act { body, action } => act(&mut b, *body, action, &id),
            StepKind::Intersect {
                temp,
                loci,
                branch,
                tol,
            } => intersect(&mut b, *temp, loci, *branch, *tol, &id),
            StepKind::IntersectDir {
                temps,
                cones,
                sign,
                branch,
            } => {
                // As the interpreter: `d` on both cones, then `sign·d`.
                let [(a1, c1), (a2, c2)] = cones.as_ref();
                let (w1, w2) = (b.dir(a1, "axis_1"), b.dir(a2, "axis_2"));
                let (c1, c2s, sg) = (lit(*c1), lit(sign * c2), b.slit(*sign));
                let (t0, t1, k) = (index(temps[0]), index(temps[1]), index(*branch));
                quote! {
                    let mut last = w.temps[#t0];
                    let d = spatial::cone_cone(ctx, #id, #w1, #c1, #w2, #c2s, &mut w.branches[#k], &mut last)?;
                    w.temps[#t0] = d;
                    w.temps[#t1] = spatial::scale(d, #sg);
                }
            }
            StepKind::Check { rows } => {
                let checks: Vec<TokenStream> = rows.iter().map(|r| check(r, &id, b.jets)).collect();
                quote!(#(#checks)*)
            }
            StepKind::Cluster(c) => self.cluster(&mut b, c, &id),
        };
        let pre = &b.pre;
        quote! {
            #marker
            {
                #(#pre)*
                #code
            }
        }
    }
}

/// One action on `body`: the runtime call `interp::spatial::act` makes.
fn act(b: &mut Block, body: usize, action: &Action, id: &Literal) -> TokenStream {
    let pose = state_pose(body);
    match action {
        Action::TranslateOnto { from, to } => {
            let (f, t) = (b.point(from), b.point(to));
            quote!(spatial::translate_onto(&mut #pose, #f, #t);)
        }
        Action::TranslateAlong { from, to, dir } => {
            let (f, t, u) = (b.point(from), b.point(to), b.dir(dir, "dir"));
            quote!(spatial::translate_along(&mut #pose, #f, #t, #u);)
        }
        Action::TranslateInPlane { from, to, normal } => {
            let (f, t, n) = (b.point(from), b.point(to), b.dir(normal, "normal"));
            quote!(spatial::translate_in_plane(&mut #pose, #f, #t, #n);)
        }
        Action::TranslateToLine { from, through, dir } => {
            let (f, q, u) = (b.point(from), b.point(through), b.dir(dir, "dir"));
            quote!(spatial::translate_to_line(&mut #pose, #f, #q, #u);)
        }
        Action::TranslateToPlane {
            from,
            through,
            normal,
        } => {
            let (f, q, n) = (b.point(from), b.point(through), b.dir(normal, "normal"));
            quote!(spatial::translate_to_plane(&mut #pose, #f, #q, #n);)
        }
        Action::SlideTo {
            from,
            origin,
            dir,
            axial0,
            input,
            sign,
        } => {
            let (f, o, u) = (b.point(from), b.point(origin), b.dir(dir, "dir"));
            let (axial0, i, sign) = (b.slit(*axial0), index(*input), lit(*sign));
            quote!(spatial::slide_to(&mut #pose, #o, #f, #u, #axial0 + inputs[#i], #sign);)
        }
        Action::RotateOnto { pivot, from, to } => {
            let (c, f, t) = (b.point(pivot), b.point(from), b.point(to));
            quote!(spatial::rotate_about_point(&mut #pose, #c, spatial::sub(#f, #c), spatial::sub(#t, #c));)
        }
        Action::AlignDir { pivot, from, to } => {
            let (c, f, t) = (b.point(pivot), b.dir(from, "from_dir"), b.dir(to, "to_dir"));
            quote!(spatial::rotate_about_point(&mut #pose, #c, #f, #t);)
        }
        Action::AxisOnto {
            pivot,
            axis,
            from,
            to,
        } => {
            let (c, a) = (b.point(pivot), b.dir(axis, "axis"));
            let (f, t) = (b.point(from), b.point(to));
            quote!(spatial::rotate_about_axis_onto(&mut #pose, #c, #a, #f, #t);)
        }
        Action::AxisDir {
            pivot,
            axis,
            from,
            to,
        } => {
            let (c, a) = (b.point(pivot), b.dir(axis, "axis"));
            let (f, t) = (b.dir(from, "from_dir"), b.dir(to, "to_dir"));
            quote!(spatial::rotate_about_axis_dir(&mut #pose, #c, #a, #f, #t);)
        }
        Action::Twist {
            pivot,
            axis,
            x1,
            x2,
            angle,
            input,
            sign,
        } => {
            let (c, a) = (b.point(pivot), b.dir(axis, "axis"));
            let (u1, u2) = (b.dir(x1, "x1"), b.dir(x2, "x2"));
            // The interpreter's target: the angle in degrees plus the input,
            // turned into a cos/sin pair by `Rot::from_degrees`; with no input
            // it adds 0, folded here to the same number.
            let target = match input {
                Some(i) if b.jets => {
                    let (degrees, i) = (b.slit(angle.to_degrees()), index(*i));
                    quote!(dofplan_runtime::Rot::from_degrees_jet(#degrees + inputs[#i]))
                }
                Some(i) => {
                    let (degrees, i) = (lit(angle.to_degrees()), index(*i));
                    quote!(dofplan_runtime::Rot::from_degrees(#degrees + inputs[#i]))
                }
                None if b.jets => {
                    let degrees = lit(angle.to_degrees() + 0.0);
                    quote!(dofplan_runtime::Rot::cst(dofplan_runtime::Rot::from_degrees(#degrees)))
                }
                None => {
                    let degrees = lit(angle.to_degrees() + 0.0);
                    quote!(dofplan_runtime::Rot::from_degrees(#degrees))
                }
            };
            let sign = lit(*sign);
            quote! {
                let (sin, cos) = spatial::twist_correction(#a, #u1, #u2, #target, #sign);
                spatial::rotate_about_axis_angle(&mut #pose, #c, #a, cos, sin);
            }
        }
        Action::AxisCondition {
            pivot,
            axis,
            v,
            w,
            cos,
            branch,
        } => {
            let (c, a) = (b.point(pivot), b.dir(axis, "axis"));
            let (vv, ww) = (b.dir(v, "v_dir"), b.dir(w, "w_dir"));
            let (cos, k) = (lit(*cos), index(*branch));
            quote! {
                let (cos, sin) = spatial::rotation_to_condition(
                    ctx, #id, #a, #vv, #ww, #cos, &mut w.branches[#k], &mut w.angles[#k],
                )?;
                spatial::rotate_about_axis_angle(&mut #pose, #c, #a, cos, sin);
            }
        }
        Action::Tilt { pivot, from, to, cos } => {
            let (c, f, t) = (b.point(pivot), b.dir(from, "from_dir"), b.dir(to, "to_dir"));
            let cos = lit(*cos);
            quote!(spatial::tilt(&mut #pose, #c, #f, #t, #cos);)
        }
        Action::Hinge { pivot, axis, turn } => {
            let (c, a) = (vec_lit(*pivot), vec_lit(*axis));
            match turn {
                HingeTurn::Degrees { offset, input, sign } => {
                    // The interpreter's `sign·(offset + input)`, the same
                    // operations in the same order (with no input, the
                    // number it computes, folded here).
                    let degrees = match input {
                        // On jets `x.mul_f64(k)`, the same product as `k * x`.
                        Some(i) if b.jets => {
                            let (k, o, i) = (lit(*sign), b.slit(*offset), index(*i));
                            quote!((#o + inputs[#i]).mul_f64(#k))
                        }
                        Some(i) => {
                            let (k, o, i) = (lit(*sign), lit(*offset), index(*i));
                            quote!(#k * (#o + inputs[#i]))
                        }
                        None => b.slit(sign * (offset + 0.0)),
                    };
                    quote!(spatial::hinge_degrees(&mut #pose, #c, #a, #degrees);)
                }
                HingeTurn::Onto { from, to } => {
                    let (f, t) = (vec_lit(*from), b.point(to));
                    quote!(spatial::hinge_onto(&mut #pose, #c, #a, #f, #t);)
                }
                HingeTurn::Dir { from, to } => {
                    let (f, t) = (vec_lit(*from), b.dir(to, "to_dir"));
                    quote!(spatial::hinge_dir(&mut #pose, #c, #a, #f, #t);)
                }
            }
        }
    }
}

/// `(centre, normal, radius)` of a circle locus, bound as `c<k>`, `n<k>`,
/// `r<k>`.
///
/// A circle of constants (a fixed hinge's) is the runtime's
/// `circle_about` evaluated here, once, rather than every frame: the same
/// function on the same numbers, so the same bits as the interpreter's.
/// Its normal is then plain numbers when `plain_normal` (the step takes it
/// as a `Factor`).
fn circle(
    b: &mut Block,
    pivot: &PointRef,
    axis: &DirRef,
    at: &PointRef,
    k: &str,
    plain_normal: bool,
) -> (Ident, Ident, Ident) {
    let sep = if k.is_empty() { "" } else { "_" };
    let (c, n, r) = (
        b.fresh(&format!("c{k}")),
        b.fresh(&format!("n{k}")),
        b.fresh(&format!("r{k}")),
    );
    if let (PointRef::Fixed(p), DirRef::Fixed(a), PointRef::Fixed(x)) = (pivot, axis, at) {
        let (cv, nv, rv) = dofplan_runtime::spatial::circle_about(*p, *a, *x);
        // A step that takes its normal as a `Factor` multiplies by a
        // constant one as plain numbers (a third of a jet product).
        let nv = if plain_normal { vec_lit(nv) } else { b.vlit(nv) };
        let (cv, rv) = (b.vlit(cv), b.slit(rv));
        b.pre.push(quote!(let (#c, #n, #r) = (#cv, #nv, #rv);));
        return (c, n, r);
    }
    let (p, a, x) = (b.point(pivot), b.dir(axis, &format!("axis{sep}{k}")), b.point(at));
    b.pre
        .push(quote!(let (#c, #n, #r) = spatial::circle_about(#p, #a, #x);));
    (c, n, r)
}

/// `(centre, radius)` of a sphere locus, bound as `cs`, `rs`; the radius
/// between two constant points evaluated here, as a constant circle's.
fn sphere(b: &mut Block, centre: &PointRef, a: &PointRef, bb: &PointRef) -> (TokenStream, TokenStream) {
    let cs = b.point(centre);
    if let (PointRef::Fixed(pa), PointRef::Fixed(pb)) = (a, bb) {
        use dofplan_runtime::spatial::{norm, sub};
        let rs = b.slit(norm(sub(*pb, *pa)));
        return (cs, b.bind("rs", rs));
    }
    let (pa, pb) = (b.point(a), b.point(bb));
    let rs = b.bind("rs", quote!(spatial::norm(spatial::sub(#pb, #pa))));
    (cs, rs)
}

/// A pseudo-marker: the intersection `interp::spatial::intersect` computes,
/// with its last position (the nearest-root policy's reference) and
/// branch read from and written to the working copy.
fn intersect(
    b: &mut Block,
    temp: usize,
    loci: &[Locus; 2],
    branch: Option<usize>,
    tol: f64,
    id: &Literal,
) -> TokenStream {
    let t = index(temp);
    let br = match branch {
        Some(k) => {
            let k = index(k);
            quote!(&mut w.branches[#k])
        }
        // One valid root: the runtime still takes a branch, which no later
        // frame reads.
        None => quote!(&mut Branch::Plus),
    };
    let last = quote!(&mut w.temps[#t]);
    let tol = lit(tol);
    let call = match loci {
        [Locus::Circle { pivot, axis, at }, Locus::Circle {
            pivot: p2,
            axis: a2,
            at: x2,
        }] => {
            let (c1, n1, r1) = circle(b, pivot, axis, at, "1", false);
            let (c2, n2, r2) = circle(b, p2, a2, x2, "2", false);
            quote!(spatial::circle_circle(ctx, #id, #c1, #n1, #r1, #c2, #n2, #r2, #tol, #br, #last)?)
        }
        [Locus::Sphere { centre, a, b: pb }, Locus::Circle { pivot, axis, at: x }]
        | [Locus::Circle { pivot, axis, at: x }, Locus::Sphere { centre, a, b: pb }] => {
            let (cs, rs) = sphere(b, centre, a, pb);
            let (c, n, r) = circle(b, pivot, axis, x, "", true);
            quote!(spatial::sphere_circle(ctx, #id, #cs, #rs, #c, #n, #r, #br, #last)?)
        }
        [Locus::Line { at, dir }, Locus::Sphere { centre, a, b: pb }]
        | [Locus::Sphere { centre, a, b: pb }, Locus::Line { at, dir }] => {
            let (cs, rs) = sphere(b, centre, a, pb);
            let (p, d) = (b.point(at), b.dir(dir, "line_dir"));
            quote!(spatial::line_sphere(ctx, #id, #p, #d, #cs, #rs, #br, #last)?)
        }
        [Locus::Line { at, dir }, Locus::Circle { pivot, axis, at: x }]
        | [Locus::Circle { pivot, axis, at: x }, Locus::Line { at, dir }] => {
            let (c, n, r) = circle(b, pivot, axis, x, "", false);
            let (p, d) = (b.point(at), b.dir(dir, "line_dir"));
            quote!(spatial::line_circle(ctx, #id, #p, #d, #c, #n, #r, #tol, #br, #last)?)
        }
        _ => unreachable!("the planner intersects only the pairs above"),
    };
    quote! {
        let root = #call;
        w.temps[#t] = root;
    }
}

/// The world frames of a check or cluster row's two markers, at `pose`.
pub(super) fn frames(r: &CheckRow, pose: &dyn Fn(usize) -> TokenStream) -> (TokenStream, TokenStream) {
    let frame = |k: usize| {
        let p = pose(r.bodies[k]);
        let (at, z, x) = (vec_lit(r.at[k]), vec_lit(r.z[k]), vec_lit(r.x[k]));
        quote!(WorldFrame::of(&#p, #at, #z, #x))
    };
    (frame(0), frame(1))
}

/// A redundant row: it must hold, or the frame breaks "inconsistent"
/// (`interp::spatial::check_gap_at`). On jets it is checked on the values.
fn check(r: &CheckRow, id: &Literal, jets: bool) -> TokenStream {
    let value_pose = |body: usize| {
        let b = index(body);
        quote!(w.poses[#b].value())
    };
    let (f1, f2) = if jets {
        frames(r, &value_pose)
    } else {
        frames(r, &state_pose)
    };
    let (kind, tol) = (row_kind(&r.kind), lit(r.tol));
    let inputs = if jets {
        quote!(input_values)
    } else {
        quote!(inputs)
    };
    quote! {
        let gap = #kind.gap(&#f1, &#f2, #inputs);
        if gap > #tol {
            ctx.fail(#id, BreakKind::Inconsistent, gap)?;
        }
    }
}

impl Emitter3<'_> {
    /// The constants naming each body and marker, and the state's marker
    /// reader (as a planar module's, with [`Marker3`](dofplan_runtime::Marker3)).
    fn names(&self) -> TokenStream {
        let plan = self.plan;
        let body_names = names::constants(plan.bodies.iter().map(String::as_str));
        let bodies = plan
            .bodies
            .iter()
            .zip(&body_names)
            .enumerate()
            .map(|(i, (b, c))| {
                let (doc, c, i) = (format!(" `{b}`"), format_ident!("{}", c), index(i));
                quote! {
                    #[doc = #doc]
                    pub const #c: usize = #i;
                }
            });
        let all_markers: Vec<(usize, String, Vec3)> = plan
            .markers
            .iter()
            .enumerate()
            .flat_map(|(i, ms)| {
                ms.iter()
                    .map(move |(m, at)| (i, format!("{}.{m}", plan.bodies[i]), *at))
            })
            .collect();
        let marker_names = names::constants(all_markers.iter().map(|(_, n, _)| n.as_str()));
        let markers = all_markers.iter().zip(&marker_names).map(|((b, name, at), c)| {
            let doc = format!(" `{name}`");
            let (c, b, at) = (format_ident!("{}", c), index(*b), vec_lit(*at));
            quote! {
                #[doc = #doc]
                pub const #c: Marker3 = Marker3::new(#name, #b, #at);
            }
        });
        let use_marker = if all_markers.is_empty() {
            quote!()
        } else {
            quote!(
                use dofplan_runtime::Marker3;
            )
        };
        quote! {
            /// Each body's index in [`BODIES`] and [`State::poses`], by name:
            /// upper-cased, other characters than ASCII letters and digits
            /// made `_`, and `_2`, `_3`, … after a name an earlier body took.
            pub mod body {
                #(#bodies)*
            }

            /// Each marker's body and local coordinates (its drawn position),
            /// named `BODY_MARKER` by the rule of `body`; read one with
            /// `State::marker` or `Marker3::world`.
            pub mod marker {
                #use_marker
                #(#markers)*
            }

            impl State {
                /// The world position of marker `m` (a constant of
                /// [`marker`]) in this state.
                #[inline]
                pub fn marker(&self, m: Marker3) -> Vec3 {
                    m.world(&self.poses)
                }
            }
        }
    }

    /// `solve`: the steps on a working copy of the state, in one function
    /// or (`chunks`) in functions of a few steps each.
    fn solve(
        &self,
        steps: Vec<TokenStream>,
        uses: &Uses,
        chunks: Option<Vec<(usize, usize)>>,
        doc: &str,
    ) -> TokenStream {
        let writes = self
            .plan
            .steps
            .iter()
            .any(|s| !matches!(s.kind, StepKind::Check { .. }));
        let mut unused = Vec::new();
        if !uses.has("inputs") {
            unused.push(quote!(let _ = inputs;));
        }
        if !uses.has("ctx") {
            unused.push(quote!(let _ = ctx;));
        }
        // As the interpreter: every moving body's rotation corrected once a
        // frame, after the steps, so composed rotations stay rigid.
        let moving: Vec<TokenStream> = (0..self.plan.bodies.len())
            .filter(|&b| self.plan.composes(b))
            .map(|b| {
                let b = index(b);
                quote!(w.poses[#b].renormalize();)
            })
            .collect();
        let Some(chunks) = chunks else {
            if !writes {
                // Only checks (or nothing): the state is read, never written.
                let take = if steps.is_empty() {
                    quote!(let _ = s;)
                } else {
                    quote!(let w = *s;)
                };
                return quote! {
                    #[doc = #doc]
                    #[inline]
                    pub fn solve(s: &mut State, inputs: &[f64], ctx: &mut Ctx) -> Result<(), Break> {
                        #(#unused)*
                        #take
                        #(#steps)*
                        Ok(())
                    }
                };
            }
            let solve = self.transaction(doc);
            return quote! {
                #solve

                /// Every step of [`solve`] in place; `solve` restores the
                /// state when one breaks.
                #[inline(always)]
                fn run_steps(w: &mut State, inputs: &[f64], ctx: &mut Ctx) -> Result<(), Break> {
                    #(#unused)*
                    #(#steps)*
                    #(#moving)*
                    Ok(())
                }
            };
        };
        let mut steps = steps.into_iter();
        let mut functions = Vec::new();
        let mut calls = Vec::new();
        for (first, last) in chunks {
            let code: Vec<TokenStream> = steps.by_ref().take(last - first + 1).collect();
            let u = Uses::of(&quote!(#(#code)*));
            let param = |name: &str| {
                if u.has(name) {
                    format_ident!("{}", name)
                } else {
                    format_ident!("_{}", name)
                }
            };
            let (inputs, ctx) = (param("inputs"), param("ctx"));
            // Named by the steps' 1-based numbers, as the comments are.
            let (f, fdoc) = if first == last {
                (
                    format_ident!("step_{}", first + 1),
                    format!(" Step {} of [`solve`], in place.", first + 1),
                )
            } else {
                (
                    format_ident!("steps_{}_to_{}", first + 1, last + 1),
                    format!(" Steps {} to {} of [`solve`], in place.", first + 1, last + 1),
                )
            };
            functions.push(quote! {
                #[doc = #fdoc]
                #[inline(never)]
                fn #f(w: &mut State, #inputs: &[f64], #ctx: &mut Ctx) -> Result<(), Break> {
                    #(#code)*
                    Ok(())
                }
            });
            calls.push(quote!(#f(w, inputs, ctx)?;));
        }
        let solve = self.transaction(doc);
        quote! {
            #solve

            /// Every step of [`solve`] in place, a few steps a function;
            /// `solve` restores the state when one breaks.
            #[inline(always)]
            fn run_steps(w: &mut State, inputs: &[f64], ctx: &mut Ctx) -> Result<(), Break> {
                #(#calls)*
                #(#moving)*
                Ok(())
            }

            #(#functions)*
        }
    }

    /// `solve` as a transaction: [`run_steps`] on the state, restored from a
    /// copy if a step breaks.
    fn transaction(&self, doc: &str) -> TokenStream {
        let why = self.note(COPY.to_string());
        quote! {
            #[doc = #doc]
            #[inline]
            pub fn solve(s: &mut State, inputs: &[f64], ctx: &mut Ctx) -> Result<(), Break> {
                #why
                let before = *s;
                let result = run_steps(s, inputs, ctx);
                if result.is_err() {
                    *s = before;
                }
                result
            }
        }
    }

    fn module(
        &self,
        steps: Vec<TokenStream>,
        chunks: Option<Vec<(usize, usize)>>,
        jet_steps: Vec<TokenStream>,
    ) -> TokenStream {
        let plan = self.plan;
        let code = quote!(#(#steps)*);
        let u = Uses::of(&code);
        let rates = self.rates(jet_steps, chunks.as_deref());
        let rate_methods = super::rates::rates_trait_methods(&quote!(Pose3));
        let name = &plan.name;
        let nb = index(plan.bodies.len());
        let nt = index(plan.temps.len());
        let nk = index(plan.branches.len());
        let ni = index(plan.inputs.len());
        let nsteps = index(plan.steps.len());
        let body_names = &plan.bodies;
        let input_names = &plan.inputs;
        let input_kinds = plan.input_kinds.iter().map(|k| match k {
            InputKind::Angle => quote!(InputKind::Angle),
            InputKind::Slide => quote!(InputKind::Slide),
        });
        let fixed = &plan.fixed;
        let temps = plan.temps.iter().map(|t| vec_lit(t.drawn));
        let initial = plan.branches.iter().map(|b| match b.initial {
            Branch::Plus => quote!(Branch::Plus),
            Branch::Minus => quote!(Branch::Minus),
        });
        let angles = plan.branches.iter().map(|b| lit(b.angle));

        // Import what the steps use, and no more: an unused import would
        // warn in the user's crate.
        let pick = |names: &[&str]| -> Vec<Ident> {
            names
                .iter()
                .filter(|n| u.has(n))
                .map(|n| format_ident!("{}", n))
                .collect()
        };
        // (The rates always use `spatial`.)
        let mut imports = vec![quote!(
            use dofplan_runtime::spatial::{self, Pose3, Vec3};
        )];
        let rows = pick(&["FrameRate", "RowKind", "WorldFrame"]);
        if !rows.is_empty() {
            imports.push(quote!(use dofplan_runtime::spatial::rows::{#(#rows),*};));
        }
        let mut cluster = pick(&["Unknowns"]);
        if u.has("cluster") {
            cluster.insert(0, format_ident!("self"));
        }
        if !cluster.is_empty() {
            imports.push(quote!(use dofplan_runtime::spatial::cluster::{#(#cluster),*};));
        }
        if u.has("numeric") {
            imports.push(quote!(
                use dofplan_runtime::numeric;
            ));
        }
        let kinds = pick(&["BreakKind"]);
        imports.push(quote!(use dofplan_runtime::{Branch, Break, #(#kinds,)* Ctx, Marker3, Solver};));
        imports.push(quote!(
            use dofplan_runtime::real::{Jet2, RateError, Real};
        ));
        imports.push(quote!(
            use dofplan_runtime::BranchPolicy;
        ));

        let doc_solve = format!(
            " Places every body for `inputs` ({}), warm-started from `s`. On a break `s` is left unchanged.",
            if plan.inputs.is_empty() {
                "none".to_string()
            } else {
                plan.inputs
                    .iter()
                    .zip(&plan.input_kinds)
                    .map(|(n, k)| {
                        format!(
                            "{n} in {}",
                            match k {
                                InputKind::Angle => "degrees",
                                InputKind::Slide => "length units",
                            }
                        )
                    })
                    .collect::<Vec<_>>()
                    .join(", ")
            }
        );
        let solve = self.solve(steps, &u, chunks, &doc_solve);
        let names = self.names();
        quote! {
            #(#imports)*

            /// Kind of an input.
            pub use dofplan_runtime::planar::InputKind;

            /// The mechanism's name.
            pub const NAME: &str = #name;
            /// Body names, in the order of [`State::poses`].
            pub const BODIES: [&str; #nb] = [#(#body_names),*];
            /// Which bodies are fixed (ground).
            pub const FIXED: [bool; #nb] = [#(#fixed),*];
            /// Input names, in the order [`solve`] takes them.
            pub const INPUTS: [&str; #ni] = [#(#input_names),*];
            /// Input kinds (angles in degrees, slides in length units).
            pub const INPUT_KINDS: [InputKind; #ni] = [#(#input_kinds),*];
            /// Number of plan steps.
            pub const STEPS: usize = #nsteps;

            /// What a frame reads from the previous one and writes.
            #[derive(Clone, Copy, Debug, PartialEq)]
            pub struct State {
                /// Body poses, in [`BODIES`] order.
                pub poses: [Pose3; #nb],
                /// Each pseudo-marker's last position (nearest-root policy,
                /// and the point later steps of the frame read).
                pub temps: [Vec3; #nt],
                /// Each branch slot's branch.
                pub branches: [Branch; #nk],
                /// Each branch slot's last root, by its sine (rotations to
                /// a condition).
                pub angles: [f64; #nk],
            }

            impl State {
                /// The drawn pose.
                pub const DRAWN: State = State {
                    poses: [Pose3::IDENTITY; #nb],
                    temps: [#(#temps),*],
                    branches: [#(#initial),*],
                    angles: [#(#angles),*],
                };
            }

            #names

            /// The compiled plan, for [`dofplan_runtime::Driver`].
            #[derive(Clone, Copy, Debug, Default)]
            pub struct Plan;

            impl Solver for Plan {
                type Pose = Pose3;
                type State = State;
                type Inputs = [f64; #ni];

                fn initial_state(&self) -> State {
                    State::DRAWN
                }

                fn initial_inputs(&self) -> [f64; #ni] {
                    [0.0; #ni]
                }

                fn poses(state: &State) -> &[Pose3] {
                    &state.poses
                }

                fn solve(&self, s: &mut State, inputs: &[f64], ctx: &mut Ctx) -> Result<(), Break> {
                    solve(s, inputs, ctx)
                }
            }

            impl dofplan_runtime::spatial::Rates3 for Plan {
                #rate_methods
            }

            #solve

            #rates
        }
    }

    /// `solve_rates` and `rates`: the steps written on jets (`steps`; a
    /// numeric cluster's by the implicit function theorem), run in one
    /// function or, for a plan split into functions (`chunks`), in the
    /// same chunks as `solve`'s.
    fn rates(&self, steps: Vec<TokenStream>, chunks: Option<&[(usize, usize)]>) -> TokenStream {
        let plan = self.plan;
        let nb = index(plan.bodies.len());
        // The steps in `run_jets` itself, or in functions of the chunks of
        // `solve` that it calls.
        let (body, functions) = match chunks {
            None => (steps, Vec::new()),
            Some(chunks) => {
                let mut steps = steps.into_iter();
                let (mut calls, mut functions) = (Vec::new(), Vec::new());
                for &(first, last) in chunks {
                    let code: Vec<TokenStream> = steps.by_ref().take(last - first + 1).collect();
                    let u = Uses::of(&quote!(#(#code)*));
                    let param = |name: &str| {
                        if u.has(name) {
                            format_ident!("{}", name)
                        } else {
                            format_ident!("_{}", name)
                        }
                    };
                    let (inputs, values, ctx) = (param("inputs"), param("input_values"), param("ctx"));
                    let (f, fdoc) = if first == last {
                        (
                            format_ident!("jets_step_{}", first + 1),
                            format!(" Step {} of [`solve`] on jets, in place.", first + 1),
                        )
                    } else {
                        (
                            format_ident!("jets_steps_{}_to_{}", first + 1, last + 1),
                            format!(
                                " Steps {} to {} of [`solve`] on jets, in place.",
                                first + 1,
                                last + 1
                            ),
                        )
                    };
                    functions.push(quote! {
                        #[doc = #fdoc]
                        #[inline(never)]
                        fn #f(w: &mut Jets<'_>, #inputs: &[Jet2], #values: &[f64], #ctx: &mut Ctx) -> Result<(), Break> {
                            #(#code)*
                            Ok(())
                        }
                    });
                    calls.push(quote!(#f(w, inputs, input_values, ctx)?;));
                }
                (calls, functions)
            }
        };
        let steps = body;
        let (nt, nk, ni) = (
            index(plan.temps.len()),
            index(plan.branches.len()),
            index(plan.inputs.len()),
        );
        let moving = (0..plan.bodies.len()).filter(|&b| plan.composes(b)).map(|b| {
            let b = index(b);
            quote!(w.poses[#b].renormalize();)
        });
        // The steps work on the poses in `out` itself.
        let body = quote! {
            let jets: [Jet2; #ni] =
                core::array::from_fn(|k| Jet2::new(inputs[k], rates[k], accelerations[k]));
            for (o, p) in out.iter_mut().zip(&s.poses) {
                *o = Pose3::cst(*p);
            }
            let mut w = Jets {
                poses: out,
                temps: s.temps.map(spatial::cst),
                branches: s.branches,
                angles: s.angles,
            };
            run_jets(&mut w, &jets, inputs, ctx)?;
            for (p, o) in s.poses.iter_mut().zip(w.poses.iter()) {
                *p = o.value();
            }
            s.temps = w.temps.map(spatial::value);
            s.branches = w.branches;
            s.angles = w.angles;
            spatial::checked3(&*w.poses).map(|_| ())
        };
        let api = super::rates::rates_functions(&quote!(Pose3), &nb, body);
        let code = quote! {
            /// [`State`] on jets: what [`solve_rates`] works on, its poses
            /// in the caller's `out`.
            struct Jets<'a> {
                poses: &'a mut [Pose3<Jet2>; #nb],
                temps: [Vec3<Jet2>; #nt],
                branches: [Branch; #nk],
                angles: [f64; #nk],
            }

            #api

            /// Every step of [`solve`] on jets, in place (checks on
            /// `input_values`).
            #[inline(always)]
            fn run_jets(w: &mut Jets<'_>, inputs: &[Jet2], input_values: &[f64], ctx: &mut Ctx) -> Result<(), Break> {
                let _ = (&w, &inputs, &input_values, &ctx);
                #(#steps)*
                #(#moving)*
                Ok(())
            }

            #(#functions)*
        };
        code
    }
}

/// Whether every numeric cluster of `plan` fits the fixed-size matrices of
/// generated code: at most [`FIXED_LIMIT`](super::FIXED_LIMIT) unknowns
/// and equations. A spatial cluster has no dynamically sized solver in the
/// runtime to fall back on (a planar one does), so `dofplan::build`
/// refuses a plan that does not fit rather than write a module rustc
/// cannot compile or a frame cannot run on the stack.
pub fn spatial_cluster_fits(plan: &Plan) -> Result<(), (usize, usize, usize)> {
    for (i, s) in plan.steps.iter().enumerate() {
        if let StepKind::Cluster(c) = &s.kind {
            let (n, m) = (c.unknowns(), c.equations());
            if n.max(m) > super::FIXED_LIMIT {
                return Err((i + 1, n, m));
            }
        }
    }
    Ok(())
}

/// Rust source of the compiled plan module of the spatial plan `plan`.
///
/// A numeric cluster is written over fixed-size matrices whatever its
/// size; see [`spatial_cluster_fits`] for the sizes that compile well.
///
/// # Panics
/// On a drag's plan (`numeric::spatial::drag_plan`): its cluster is solved
/// by task priority, which only the interpreter has. The analysis never
/// makes one.
pub fn emit_spatial(plan: &Plan) -> String {
    emit_spatial_chunked(plan, CHUNK_WEIGHT)
}

/// [`emit_spatial`] with functions of at most `chunk_weight` tokens of
/// steps (1 puts every step in a function of its own: tests use it to
/// check the split form on small mechanisms).
///
/// # Panics
/// As [`emit_spatial`].
pub fn emit_spatial_chunked(plan: &Plan, chunk_weight: usize) -> String {
    let e = Emitter3 {
        plan,
        notes: RefCell::new(Vec::new()),
        jets: Cell::new(false),
    };
    let steps: Vec<TokenStream> = (0..plan.steps.len()).map(|i| e.step(i)).collect();
    let weights: Vec<usize> = steps.iter().map(|s| Uses::of(s).weight).collect();
    let chunks = partition(&weights, chunk_weight);
    // The steps on jets, for the rates (in the same chunks as `solve`'s).
    e.jets.set(true);
    let jet_steps = (0..plan.steps.len()).map(|i| e.step(i)).collect();
    e.jets.set(false);
    let tokens = e.module(steps, chunks, jet_steps);
    let file = syn::parse2::<syn::File>(tokens).expect("the emitter produces valid Rust");
    let pretty = prettyplease::unparse(&file);
    let notes = e.notes.into_inner();
    let mut out = format!(
        "// @generated by dofplan from {} — do not edit.\n// Compiled plan of spatial mechanism `{}`: {} steps, {} pseudo-markers, {} branch slots.\n// Regenerate with `dofplan emit {}` or by rebuilding the crate that compiles it.\n\n",
        plan.source,
        plan.name,
        plan.steps.len(),
        plan.temps.len(),
        plan.branches.len(),
        plan.source
    );
    // Comments are not tokens: each step and each cluster row was marked by
    // a macro call that is replaced here by its text.
    for line in pretty.lines() {
        let trimmed = line.trim_start();
        let indent = &line[..line.len() - trimmed.len()];
        if let Some(rest) = trimmed.strip_prefix("__dofplan_step!(") {
            let i: usize = rest.trim_end_matches(");").parse().expect("step marker");
            let step = &plan.steps[i];
            let serves = if step.serves.is_empty() {
                String::new()
            } else {
                format!("  [{}]", step.serves.join(", "))
            };
            out.push_str(&format!("{indent}// {i}: {}{serves}\n", step.text));
        } else if let Some(rest) = trimmed.strip_prefix("__dofplan_note!(") {
            let i: usize = rest.trim_end_matches(");").parse().expect("note marker");
            out.push_str(&format!("{indent}// {}\n", notes[i]));
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

/// Runs of steps `(first, last)` of at most `limit` tokens each (a larger
/// step stays whole), or `None` when all fit in one function.
fn partition(weights: &[usize], limit: usize) -> Option<Vec<(usize, usize)>> {
    if weights.iter().sum::<usize>() <= limit {
        return None;
    }
    let mut chunks = Vec::new();
    let (mut start, mut weight) = (0, 0);
    for (i, &w) in weights.iter().enumerate() {
        if i > start && weight + w > limit {
            chunks.push((start, i - 1));
            (start, weight) = (i, 0);
        }
        weight += w;
    }
    chunks.push((start, weights.len() - 1));
    Some(chunks)
}
