//! Each spatial step's code: one block calling exactly the runtime
//! function the interpreter ([`crate::interp::spatial`]) calls for it, on
//! the points and directions it reads bound to named locals.

use std::collections::{HashMap, HashSet};

use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::quote;

use dofplan_runtime::spatial::rows::RowKind;
use dofplan_runtime::spatial::Vec3;

use super::Emitter;
use crate::emit::fold::{plus_input, times};
use crate::emit::{ident_for, index, lit};
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

/// A body's pose in the frame's working copy.
pub(super) fn state_pose(body: usize) -> TokenStream {
    let b = index(body);
    quote!(w.poses[#b])
}

impl Emitter<'_> {
    pub(super) fn step(&self, i: usize) -> TokenStream {
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
                    let d = spatial::cone_cone(ctx, #id, spatial::Cone::new(#w1, #c1), spatial::Cone::new(#w2, #c2s), spatial::Slot::new(&mut w.branches[#k], &mut last))?;
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

/// One action on `body` (step `id`): the runtime call
/// `interp::spatial::act` makes, a translation, a rotation, or a hinged
/// body's pose set outright.
fn act(b: &mut Block, body: usize, action: &Action, id: &Literal) -> TokenStream {
    match action {
        Action::TranslateOnto { .. }
        | Action::TranslateAlong { .. }
        | Action::TranslateInPlane { .. }
        | Action::TranslateToLine { .. }
        | Action::TranslateToPlane { .. }
        | Action::SlideTo { .. } => translate(b, body, action),
        Action::Twist { .. } => twist(b, body, action),
        Action::Hinge { .. } => hinge(b, body, action),
        _ => rotate(b, body, action, id),
    }
}

/// A translation: the body keeps its rotation.
fn translate(b: &mut Block, body: usize, action: &Action) -> TokenStream {
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
            let (i, sign) = (index(*input), lit(*sign));
            let at = plus_input(*axial0, b.slit(*axial0), quote!(inputs[#i]));
            quote!(spatial::slide_to(&mut #pose, #o, #f, #u, #at, #sign);)
        }
        _ => unreachable!("not a translation"),
    }
}

/// A rotation about a point or an axis (a branch for a rotation to a
/// condition, whose sine the slot keeps).
fn rotate(b: &mut Block, body: usize, action: &Action, id: &Literal) -> TokenStream {
    let pose = state_pose(body);
    match action {
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
                    ctx, #id, #a, #vv, #ww, #cos, spatial::Slot::new(&mut w.branches[#k], &mut w.angles[#k]),
                )?;
                spatial::rotate_about_axis_angle(&mut #pose, #c, #a, cos, sin);
            }
        }
        Action::Tilt { pivot, from, to, cos } => {
            let (c, f, t) = (b.point(pivot), b.dir(from, "from_dir"), b.dir(to, "to_dir"));
            let cos = lit(*cos);
            quote!(spatial::tilt(&mut #pose, #c, #f, #t, #cos);)
        }
        _ => unreachable!("not a rotation"),
    }
}

/// A twist about a joint's axis to its angle, plus the input's.
fn twist(b: &mut Block, body: usize, action: &Action) -> TokenStream {
    let pose = state_pose(body);
    let Action::Twist {
        pivot,
        axis,
        x1,
        x2,
        angle,
        input,
        sign,
    } = action
    else {
        unreachable!("a twist")
    };
    let (c, a) = (b.point(pivot), b.dir(axis, "axis"));
    let (u1, u2) = (b.dir(x1, "x1"), b.dir(x2, "x2"));
    // The interpreter's target: the angle in degrees plus the input,
    // turned into a cos/sin pair by `Rot::from_degrees`; with no input
    // it adds 0, folded here to the same number.
    let target = match input {
        Some(i) => {
            let (degrees, i) = (angle.to_degrees(), index(*i));
            let at = plus_input(degrees, b.slit(degrees), quote!(inputs[#i]));
            if b.jets {
                quote!(dofplan_runtime::Rot::from_degrees_jet(#at))
            } else {
                quote!(dofplan_runtime::Rot::from_degrees(#at))
            }
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

/// A body hinged on a fixed line, its pose set outright from the drawn one.
fn hinge(b: &mut Block, body: usize, action: &Action) -> TokenStream {
    let pose = state_pose(body);
    let Action::Hinge { pivot, axis, turn } = action else {
        unreachable!("a hinge")
    };
    let (c, a) = (vec_lit(*pivot), vec_lit(*axis));
    match turn {
        HingeTurn::Degrees { offset, input, sign } => {
            // The interpreter's `sign·(offset + input)`, the same
            // operations in the same order (with no input, the
            // number it computes, folded here).
            let degrees = match input {
                // On jets `x.mul_f64(k)`, the same product as `k * x`.
                Some(i) => {
                    let i = index(*i);
                    let sum = plus_input(*offset, b.slit(*offset), quote!(inputs[#i]));
                    times(*sign, sum, b.jets, *offset != 0.0)
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

/// `(centre, normal, radius)` of a circle locus, bound as `c<k>`, `n<k>`,
/// `r<k>` (the step takes them as `spatial::Circle::new(c<k>, n<k>, r<k>)`).
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
/// with its slot (its last position, the nearest-root policy's reference,
/// and its branch) read from and written to the working copy.
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
    let slot = quote!(spatial::Slot::new(#br, &mut w.temps[#t]));
    let tol = lit(tol);
    let call = match loci {
        [Locus::Circle { pivot, axis, at }, Locus::Circle {
            pivot: p2,
            axis: a2,
            at: x2,
        }] => {
            let (c1, n1, r1) = circle(b, pivot, axis, at, "1", false);
            let (c2, n2, r2) = circle(b, p2, a2, x2, "2", false);
            quote!(spatial::circle_circle(ctx, #id, spatial::Circle::new(#c1, #n1, #r1), spatial::Circle::new(#c2, #n2, #r2), #tol, #slot)?)
        }
        [Locus::Sphere { centre, a, b: pb }, Locus::Circle { pivot, axis, at: x }]
        | [Locus::Circle { pivot, axis, at: x }, Locus::Sphere { centre, a, b: pb }] => {
            let (cs, rs) = sphere(b, centre, a, pb);
            let (c, n, r) = circle(b, pivot, axis, x, "", true);
            quote!(spatial::sphere_circle(ctx, #id, spatial::Sphere::new(#cs, #rs), spatial::Circle::new(#c, #n, #r), #slot)?)
        }
        [Locus::Line { at, dir }, Locus::Sphere { centre, a, b: pb }]
        | [Locus::Sphere { centre, a, b: pb }, Locus::Line { at, dir }] => {
            let (cs, rs) = sphere(b, centre, a, pb);
            let (p, d) = (b.point(at), b.dir(dir, "line_dir"));
            quote!(spatial::line_sphere(ctx, #id, spatial::Line::new(#p, #d), spatial::Sphere::new(#cs, #rs), #slot)?)
        }
        [Locus::Line { at, dir }, Locus::Circle { pivot, axis, at: x }]
        | [Locus::Circle { pivot, axis, at: x }, Locus::Line { at, dir }] => {
            let (c, n, r) = circle(b, pivot, axis, x, "", false);
            let (p, d) = (b.point(at), b.dir(dir, "line_dir"));
            quote!(spatial::line_circle(ctx, #id, spatial::Line::new(#p, #d), spatial::Circle::new(#c, #n, #r), #tol, #slot)?)
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
