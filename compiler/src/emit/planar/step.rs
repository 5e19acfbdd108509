//! Each planar step's code: one block calling the runtime function the
//! interpreter calls for it, on the points and directions it reads bound
//! to named locals.

use proc_macro2::TokenStream;
use quote::{format_ident, quote};

use super::{lit, Emitter};
use crate::emit::fold::{plus_input, times};
use crate::plan::{Affine, DirRef, Line, PointRef, Rel, StepKind};

impl Emitter<'_> {
    /// Binds a point to a local inside a step's block and returns the
    /// expression that names it.
    pub(super) fn point(&self, p: &PointRef, prelude: &mut Vec<TokenStream>) -> TokenStream {
        match p {
            PointRef::Fixed { at, name } if self.design.is_some() => self.drawn_point(0, *at, Some(name)),
            PointRef::Fixed { at, .. } => self.plit(*at),
            PointRef::Marker { body, local, name } => {
                let id = self.local_point(name, prelude);
                // A marker's local position is a constant of its body: a
                // plain number even on jets and lanes (`Pose::world`).
                let (b, l) = (self.pose(*body), self.drawn_point(*body, *local, Some(name)));
                prelude.push(quote!(let #id = #b.world(#l);));
                quote!(#id)
            }
            PointRef::Slid {
                body,
                local,
                dir,
                input,
                sign,
                name,
            } => {
                let id = self.local_point(name, prelude);
                let b = self.pose(*body);
                let u = &self.input_idents[*input];
                let u = if *sign < 0.0 { quote!((-#u)) } else { quote!(#u) };
                let [lx, ly] = self.drawn_coords(*body, *local, Some(name));
                // The slide direction is a constant: on jets and lanes a
                // multiplication by a plain number. Outside a rolled run
                // (whose rows share one code) a product by ±1 and a zero
                // added to the input itself are not written out.
                let (ux, uy) = if self.row.borrow().is_some() {
                    let (dx, dy) = (self.lit(dir[0]), self.lit(dir[1]));
                    let (x, y) = if self.jets {
                        (quote!(#u.mul_f64(#dx)), quote!(#u.mul_f64(#dy)))
                    } else {
                        (quote!(#u * #dx), quote!(#u * #dy))
                    };
                    (quote!(#lx + #x), quote!(#ly + #y))
                } else {
                    // A zero coordinate is folded away only where it is a
                    // constant, not a candidate's number.
                    let raw = *sign > 0.0 && self.design.is_none();
                    let coordinate = |l: f64, lt: TokenStream, d: f64| {
                        let x = if d.abs() == 1.0 {
                            times(d, u.clone(), self.jets, false)
                        } else if self.jets {
                            let d = lit(d);
                            quote!(#u.mul_f64(#d))
                        } else {
                            let d = lit(d);
                            quote!(#u * #d)
                        };
                        if raw && d == 1.0 {
                            plus_input(l, lt, x)
                        } else {
                            quote!(#lt + #x)
                        }
                    };
                    (coordinate(local[0], lx, dir[0]), coordinate(local[1], ly, dir[1]))
                };
                // On a fixed body (at its drawn pose, the identity, as
                // `PointRef::Fixed` takes it) the carried point is the world
                // point: no rotation to multiply by.
                if self.plan.bodies[*body].fixed {
                    prelude.push(quote!(let #id = [#ux, #uy];));
                } else {
                    prelude.push(quote!(let #id = #b.world_carried([#ux, #uy]);));
                }
                quote!(#id)
            }
            PointRef::Temp { id } => {
                let t = self.temp(*id);
                quote!(#t)
            }
        }
    }

    pub(super) fn dir(&self, d: &DirRef, name: &str, prelude: &mut Vec<TokenStream>) -> TokenStream {
        match d {
            DirRef::Fixed(v) => self.plit(*v),
            DirRef::Body { body, local } => {
                let id = format_ident!("{}", name);
                let (b, l) = (self.pose(*body), self.point_lit(*local));
                prelude.push(quote!(let #id = #b.world_dir(#l);));
                quote!(#id)
            }
        }
    }

    /// The code of step `i`: its marker comment, then the runtime call of
    /// its kind.
    pub(super) fn step(&self, i: usize) -> TokenStream {
        let step = &self.plan.steps[i];
        let id = self.step_id(i);
        let marker = self.step_marker(i);
        let code = match &step.kind {
            StepKind::Orient { body, from, rel } => self.orient(*body, *from, rel),
            StepKind::Turn { body, angle } => self.turn(*body, angle),
            StepKind::Shift {
                body,
                local,
                carrier,
                at,
                dir,
                slide,
                name,
            } => self.shift(*body, *local, *carrier, (*at, *dir), slide, name),
            StepKind::Anchor { body, local, at } => self.anchor(*body, *local, at),
            StepKind::Align {
                body,
                p,
                p_at,
                q,
                q_at,
                redundant,
            } => self.align(&id, *body, [*p, *q], [p_at, q_at], *redundant),
            StepKind::CircleCircle {
                out,
                c1,
                r1,
                c2,
                r2,
                branch,
            } => self.circle_circle(&id, *out, [(c1, *r1), (c2, *r2)], *branch),
            StepKind::CircleLine {
                out,
                c,
                r,
                line,
                branch,
            } => self.circle_line(&id, *out, (c, *r), line, *branch),
            StepKind::LineLine { out, a, b } => self.line_line(&id, *out, a, b),
            StepKind::Within {
                at,
                dir,
                pin,
                ends,
                arc,
            } => self.within(&id, [at, pin], dir, *ends, *arc),
            StepKind::Cluster { params, rows, .. }
                if Self::fixed_cluster(step.kind.cluster_size().0, step.kind.cluster_size().1) =>
            {
                let size = step.kind.cluster_size();
                let code = if self.jets {
                    self.fixed_cluster_rates(&quote!(#id), params, rows, size)
                } else {
                    self.fixed_cluster_step(&quote!(#id), params, rows, size, &mut Vec::new(), false)
                };
                quote!({ #code })
            }
            StepKind::Cluster { params, rows, .. } => {
                return self.dynamic_cluster_step(i, &id, &marker, params, rows, &mut Vec::new());
            }
            StepKind::TurnLine {
                body,
                pivot,
                target,
                dir,
                kappa,
                branch,
            } => self.turn_line(&id, *body, [pivot, target], *dir, *kappa, *branch),
        };
        quote! {
            #marker
            #code
        }
    }

    /// Sets a body's rotation: from another body's (`from`), turned by
    /// `rel`, or outright.
    fn orient(&self, body: usize, from: Option<usize>, rel: &Rel) -> TokenStream {
        let b = self.pose(body);
        let r = match rel {
            Rel::Identity if self.jets => quote!(Rot::cst(Rot::IDENTITY)),
            Rel::Identity => quote!(Rot::IDENTITY),
            Rel::Input { input, inverse } => {
                let u = &self.input_idents[*input];
                if *inverse {
                    quote!(#u.inverse())
                } else {
                    quote!(#u)
                }
            }
        };
        match from {
            Some(f) => {
                let f = self.pose(f);
                quote!(planar::orient(&mut #b, #f.rot, #r);)
            }
            None => quote!(planar::set_rotation(&mut #b, #r);),
        }
    }

    /// An affine function of the inputs in the step's numbers:
    /// `c·inputs[k] + … + constant`.
    fn affine(&self, a: &Affine) -> TokenStream {
        let mut sum: Option<TokenStream> = None;
        for &(k, c) in &a.terms {
            let i = super::index(k);
            let term = times(c, quote!(inputs[#i]), self.jets, false);
            sum = Some(match sum {
                None => term,
                Some(s) => quote!(#s + #term),
            });
        }
        match sum {
            None => self.slit(a.constant),
            Some(s) if a.constant == 0.0 => s,
            Some(s) => {
                let c = self.slit(a.constant);
                quote!(#s + #c)
            }
        }
    }

    /// Sets a geared body's rotation: its angle in degrees, affine in the
    /// inputs, turned into a cos/sin pair as an angle input is.
    fn turn(&self, body: usize, angle: &Affine) -> TokenStream {
        let b = self.pose(body);
        let degrees = self.affine(angle);
        let rot = if self.dual {
            quote!(Rot::<Dual>::cst(Rot::from_degrees(#degrees)))
        } else if self.lanes {
            quote!(Rot::from_degrees_lanes(#degrees))
        } else if self.jets {
            quote!(Rot::from_degrees_jet(#degrees))
        } else {
            quote!(Rot::from_degrees(#degrees))
        };
        quote!(planar::set_rotation(&mut #b, #rot);)
    }

    /// Moves a rack along its slide: its marker onto the carrier's point
    /// `at + slide·dir` (the carried point of `PointRef::Slid`, with the
    /// slide set by the pinion).
    fn shift(
        &self,
        body: usize,
        local: [f64; 2],
        carrier: usize,
        (at, dir): ([f64; 2], [f64; 2]),
        slide: &Affine,
        name: &str,
    ) -> TokenStream {
        let u = self.affine(slide);
        let [lx, ly] = self.drawn_coords(carrier, at, None);
        let (dx, dy) = (self.lit(dir[0]), self.lit(dir[1]));
        let (x, y) = if self.jets {
            (quote!(slide.mul_f64(#dx)), quote!(slide.mul_f64(#dy)))
        } else {
            (quote!(slide * #dx), quote!(slide * #dy))
        };
        let carried = quote!([#lx + #x, #ly + #y]);
        let target = if self.plan.bodies[carrier].fixed {
            carried
        } else {
            let c = self.pose(carrier);
            quote!(#c.world_carried(#carried))
        };
        let b = self.pose(body);
        let l = self.drawn_point(body, local, Some(name));
        quote!({
            let slide = #u;
            let at = #target;
            planar::anchor(&mut #b, #l, at);
        })
    }

    /// Translates a body so its point `local` lands on `at`.
    fn anchor(&self, body: usize, local: [f64; 2], at: &PointRef) -> TokenStream {
        let at_ref = at;
        let mut pre = Vec::new();
        let at = self.point(at, &mut pre);
        let (b, l) = (self.pose(body), self.drawn_point_at(body, local, at_ref));
        quote!({
            #(#pre)*
            planar::anchor(&mut #b, #l, #at);
        })
    }

    /// Places a body by two of its points; a redundant alignment checks
    /// the distance between them.
    fn align(
        &self,
        id: &TokenStream,
        body: usize,
        [p, q]: [[f64; 2]; 2],
        [p_at, q_at]: [&PointRef; 2],
        redundant: bool,
    ) -> TokenStream {
        let mut pre = Vec::new();
        let (p_ref, q_ref) = (p_at, q_at);
        let p_at = self.point(p_at, &mut pre);
        let q_at = self.point(q_at, &mut pre);
        let (b, p, q) = (
            self.pose(body),
            self.drawn_point_at(body, p, p_ref),
            self.drawn_point_at(body, q, q_ref),
        );
        let call = if redundant {
            quote!(planar::align_consistent(ctx, #id, &mut #b, #p, #p_at, #q, #q_at)?;)
        } else {
            quote!(planar::align(&mut #b, #p, #p_at, #q, #q_at);)
        };
        quote!({
            #(#pre)*
            #call
        })
    }

    /// A pseudo-marker on two circles, on its branch.
    fn circle_circle(
        &self,
        id: &TokenStream,
        out: usize,
        [(c1, r1), (c2, r2)]: [(&PointRef, f64); 2],
        branch: usize,
    ) -> TokenStream {
        let mut pre = Vec::new();
        let t = &self.temp(out);
        let (c1_ref, c2_ref) = (c1, c2);
        let c1 = self.point(c1, &mut pre);
        let c2 = self.point(c2, &mut pre);
        let (r1, r2, k) = (
            self.radius(r1, c1_ref, out),
            self.radius(r2, c2_ref, out),
            self.index(branch),
        );
        quote! {
            let #t = {
                #(#pre)*
                planar::circle_circle(ctx, #id, planar::Circle::new(#c1, #r1), planar::Circle::new(#c2, #r2), planar::Slot::new(&mut branches[#k], &mut last[#k]))?
            };
        }
    }

    /// A pseudo-marker on a circle and a line, on its branch.
    fn circle_line(
        &self,
        id: &TokenStream,
        out: usize,
        (c, r): (&PointRef, f64),
        line: &Line,
        branch: usize,
    ) -> TokenStream {
        let mut pre = Vec::new();
        let t = &self.temp(out);
        let c_ref = c;
        let c = self.point(c, &mut pre);
        let p = self.point(&line.through, &mut pre);
        // A fixed direction stays a pair of plain numbers: the
        // step multiplies by it at a third of a jet product's cost.
        let d = match &line.dir {
            DirRef::Fixed(v) => self.point_lit(*v),
            body => self.dir(body, "line_dir", &mut pre),
        };
        let (r, k) = (self.radius(r, c_ref, out), self.index(branch));
        quote! {
            let #t = {
                #(#pre)*
                planar::circle_line(ctx, #id, planar::Circle::new(#c, #r), planar::Line::new(#p, #d), planar::Slot::new(&mut branches[#k], &mut last[#k]))?
            };
        }
    }

    /// A pseudo-marker where two lines cross.
    fn line_line(&self, id: &TokenStream, out: usize, a: &Line, b: &Line) -> TokenStream {
        let mut pre = Vec::new();
        let t = &self.temp(out);
        let p1 = self.point(&a.through, &mut pre);
        let d1 = self.dir(&a.dir, "dir_a", &mut pre);
        let p2 = self.point(&b.through, &mut pre);
        let d2 = self.dir(&b.dir, "dir_b", &mut pre);
        quote! {
            let #t = {
                #(#pre)*
                planar::line_line(ctx, #id, #p1, #d1, #p2, #d2)?
            };
        }
    }

    /// Checks a pin against its slot's ends.
    fn within(
        &self,
        id: &TokenStream,
        [at, pin]: [&PointRef; 2],
        dir: &DirRef,
        ends: [f64; 2],
        arc: bool,
    ) -> TokenStream {
        let mut pre = Vec::new();
        let a = self.point(at, &mut pre);
        let d = self.dir(dir, "slot_dir", &mut pre);
        let p = self.point(pin, &mut pre);
        let (lo, hi) = (self.lit(ends[0]), self.lit(ends[1]));
        let check = if arc {
            quote!(planar::within_arc)
        } else {
            quote!(planar::within_ends)
        };
        quote!({
            #(#pre)*
            #check(ctx, #id, #a, #d, #p, [#lo, #hi])?;
        })
    }

    /// Turns a body about `pivot` until its line (at angle `dir`, offset
    /// `kappa`) passes through `target`, on its branch.
    fn turn_line(
        &self,
        id: &TokenStream,
        body: usize,
        [pivot, target]: [&PointRef; 2],
        dir: [f64; 2],
        kappa: f64,
        branch: usize,
    ) -> TokenStream {
        let mut pre = Vec::new();
        let pv = self.point(pivot, &mut pre);
        let tg = self.point(target, &mut pre);
        let (b, d, kp, k) = (
            self.pose(body),
            self.plit(dir),
            self.line_offset(kappa, pivot, target, dir),
            self.index(branch),
        );
        quote!({
            #(#pre)*
            #b.rot = planar::turn_line_through(ctx, #id, #pv, #tg, #d, #kp, planar::Slot::new(&mut branches[#k], &mut last[#k]))?;
        })
    }
}
