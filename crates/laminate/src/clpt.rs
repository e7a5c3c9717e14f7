//! Classical laminate plate theory (CLPT): reduced stiffness `Q`, transformed `Q̄(θ)`, the `ABD`
//! matrix of a layup and its mid-plane response to mechanical, thermal and piezoelectric loads.
//!
//! # Conventions
//!
//! * Layers are listed **bottom to top**: the first layer occupies the most negative `z`. The
//!   reference plane `z = 0` is the geometric mid-plane of the whole layup.
//! * Strains use engineering shear: `ε = (εx, εy, γxy)`, curvatures `κ = (κx, κy, κxy)` (1/mm),
//!   force resultants `N` (mN/mm), moment resultants `M` (mN·mm/mm = mN).
//! * Constitutive law: `[N; M] = [A B; B D] [ε0; κ] − [N_free; M_free]`, where the free
//!   (thermal + piezoelectric) resultants are `N_free = Σ Q̄ ε_free t`,
//!   `M_free = ½ Σ Q̄ ε_free (z_top² − z_bot²)`. Hence, for applied `N, M`,
//!   `[ε0; κ] = ABD⁻¹ ([N; M] + [N_free; M_free])`.
//! * Ply angle θ (rad) rotates the ply's axis 1 from the laminate x axis towards y.
//! * Units: `A` mN/mm, `B` mN, `D` mN·mm; `Q`, `Q̄` mN/mm²; temperatures are differences in K.
//! * A piezoelectric ply under voltage `V` (V) sees the through-thickness field `E3 = V / t`
//!   (V/mm; positive along the ply's poling direction, which we take as +z) and the free strain
//!   `d31 · E3` in x and y (no shear).

use std::ops::AddAssign;

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};
use paritysim_error::{Error, Result, check_finite, check_positive};

use crate::material::{Material, MaterialClass};

/// Reduced (plane-stress) stiffness `Q` of a material in its principal axes, mN/mm².
///
/// `Q11 = E1/(1 − ν12ν21)`, `Q22 = E2/(1 − ν12ν21)`, `Q12 = ν12 E2/(1 − ν12ν21)`, `Q66 = G12`.
pub fn reduced_stiffness(m: &Material) -> Matrix3<f64> {
    let denom = 1.0 - m.nu12() * m.nu21();
    let q11 = m.e1() / denom;
    let q22 = m.e2() / denom;
    let q12 = m.nu12() * m.e2() / denom;
    Matrix3::new(q11, q12, 0.0, q12, q22, 0.0, 0.0, 0.0, m.g12())
}

/// Transformed reduced stiffness `Q̄(θ)` of a ply rotated by `theta` (rad), mN/mm².
///
/// Standard transformation (e.g. Jones, *Mechanics of Composite Materials*, eq. 2.85) with
/// engineering shear strain.
pub fn transformed_stiffness(q: &Matrix3<f64>, theta: f64) -> Matrix3<f64> {
    let (s, c) = theta.sin_cos();
    let (c2, s2) = (c * c, s * s);
    let (c4, s4, c2s2) = (c2 * c2, s2 * s2, c2 * s2);
    let (q11, q12, q22, q66) = (q[(0, 0)], q[(0, 1)], q[(1, 1)], q[(2, 2)]);
    let b11 = q11 * c4 + 2.0 * (q12 + 2.0 * q66) * c2s2 + q22 * s4;
    let b12 = (q11 + q22 - 4.0 * q66) * c2s2 + q12 * (c4 + s4);
    let b22 = q11 * s4 + 2.0 * (q12 + 2.0 * q66) * c2s2 + q22 * c4;
    let b16 = (q11 - q12 - 2.0 * q66) * c2 * c * s + (q12 - q22 + 2.0 * q66) * s2 * s * c;
    let b26 = (q11 - q12 - 2.0 * q66) * s2 * s * c + (q12 - q22 + 2.0 * q66) * c2 * c * s;
    let b66 = (q11 + q22 - 2.0 * q12 - 2.0 * q66) * c2s2 + q66 * (c4 + s4);
    Matrix3::new(b11, b12, b16, b12, b22, b26, b16, b26, b66)
}

/// Thermal expansion of a material rotated by `theta` (rad) in laminate axes,
/// `(αx, αy, αxy)` with engineering shear, 1/K.
pub fn transformed_expansion(m: &Material, theta: f64) -> Vector3<f64> {
    let (s, c) = theta.sin_cos();
    let (a1, a2) = (m.alpha1(), m.alpha2());
    Vector3::new(
        a1 * c * c + a2 * s * s,
        a1 * s * s + a2 * c * c,
        2.0 * (a1 - a2) * c * s,
    )
}

/// One ply: a material, a thickness (mm, > 0) and an angle (rad).
#[derive(Clone, Debug, PartialEq)]
pub struct Ply {
    material: Material,
    thickness: f64,
    angle: f64,
}

impl Ply {
    /// A ply of `thickness` mm (finite, > 0) at `angle` rad (finite).
    pub fn new(material: Material, thickness: f64, angle: f64) -> Result<Ply> {
        check_positive("thickness", thickness)?;
        check_finite("angle", angle)?;
        Ok(Ply {
            material,
            thickness,
            angle,
        })
    }
    /// The ply material.
    pub fn material(&self) -> &Material {
        &self.material
    }
    /// Thickness, mm.
    pub fn thickness(&self) -> f64 {
        self.thickness
    }
    /// Angle of axis 1 from the laminate x axis, rad.
    pub fn angle(&self) -> f64 {
        self.angle
    }
    /// `Q̄` of this ply, mN/mm².
    pub fn q_bar(&self) -> Matrix3<f64> {
        transformed_stiffness(&reduced_stiffness(&self.material), self.angle)
    }
}

/// A named material layer of a PC-MEMS laminate: one ply, or a pre-cured sub-stack such as the
/// 0-90-0 carbon-fibre layer of §4.4.2 (three plies).
#[derive(Clone, Debug, PartialEq)]
pub struct Layer {
    name: String,
    plies: Vec<Ply>,
}

impl Layer {
    /// A single-ply layer (`thickness` mm, `angle` rad).
    pub fn single(
        name: impl Into<String>,
        material: Material,
        thickness: f64,
        angle: f64,
    ) -> Result<Layer> {
        Layer::from_plies(name, vec![Ply::new(material, thickness, angle)?])
    }

    /// A layer made of several plies listed bottom to top; `Error::Geometry` if empty.
    pub fn from_plies(name: impl Into<String>, plies: Vec<Ply>) -> Result<Layer> {
        let name = name.into();
        if plies.is_empty() {
            return Err(Error::Geometry(format!("layer `{name}` has no plies")));
        }
        Ok(Layer { name, plies })
    }

    /// The cured 0-90-0 carbon-fibre layer of §4.4.2: three equal plies of
    /// [`crate::library::cf_prepreg_ud`] at `angle`, `angle + 90°`, `angle` (rad);
    /// `thickness` is the whole layer (mm), 0.100 in Mobee.
    pub fn cf_0_90_0(name: impl Into<String>, thickness: f64, angle: f64) -> Result<Layer> {
        check_positive("thickness", thickness)?;
        check_finite("angle", angle)?;
        let cf = crate::material::library::cf_prepreg_ud();
        let t = thickness / 3.0;
        let half_pi = std::f64::consts::FRAC_PI_2;
        Layer::from_plies(
            name,
            vec![
                Ply::new(cf.clone(), t, angle)?,
                Ply::new(cf.clone(), t, angle + half_pi)?,
                Ply::new(cf, t, angle)?,
            ],
        )
    }

    /// Layer name.
    pub fn name(&self) -> &str {
        &self.name
    }
    /// Plies, bottom to top.
    pub fn plies(&self) -> &[Ply] {
        &self.plies
    }
    /// Total thickness, mm.
    pub fn thickness(&self) -> f64 {
        self.plies.iter().map(Ply::thickness).sum()
    }
    /// Areal mass, mg/mm².
    pub fn areal_mass(&self) -> f64 {
        self.plies
            .iter()
            .map(|p| p.thickness * p.material.density())
            .sum()
    }
    /// Class of the layer (that of its first ply's material).
    pub fn class(&self) -> MaterialClass {
        self.plies[0].material.class()
    }
    /// `true` if any ply is piezoelectric.
    pub fn is_piezo(&self) -> bool {
        self.plies.iter().any(|p| p.material.is_piezo())
    }
}

/// The `A`, `B`, `D` blocks of a layup (about its geometric mid-plane).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Abd {
    /// Extensional stiffness, mN/mm.
    pub a: Matrix3<f64>,
    /// Coupling stiffness, mN.
    pub b: Matrix3<f64>,
    /// Bending stiffness, mN·mm.
    pub d: Matrix3<f64>,
}

impl Abd {
    /// The 6×6 matrix `[A B; B D]`.
    pub fn matrix(&self) -> Matrix6<f64> {
        let mut m = Matrix6::zeros();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&self.a);
        m.fixed_view_mut::<3, 3>(0, 3).copy_from(&self.b);
        m.fixed_view_mut::<3, 3>(3, 0).copy_from(&self.b);
        m.fixed_view_mut::<3, 3>(3, 3).copy_from(&self.d);
        m
    }

    /// The compliance `[a b; bᵀ d] = [A B; B D]⁻¹` (units inverse to [`Abd::matrix`]).
    /// `Error::Singular` if the stiffness is not positive definite.
    pub fn compliance(&self) -> Result<Matrix6<f64>> {
        let m = self.matrix();
        let inv = m
            .cholesky()
            .map(|c| c.inverse())
            .ok_or_else(|| Error::Singular("ABD matrix is not positive definite".into()))?;
        if inv.iter().all(|v| v.is_finite()) {
            Ok(inv)
        } else {
            Err(Error::Singular("ABD inverse is not finite".into()))
        }
    }

    /// Solves `[A B; B D] x = rhs`; `Error::Singular` if not positive definite.
    pub fn solve(&self, rhs: &Vector6<f64>) -> Result<Vector6<f64>> {
        let chol = self
            .matrix()
            .cholesky()
            .ok_or_else(|| Error::Singular("ABD matrix is not positive definite".into()))?;
        let x = chol.solve(rhs);
        if x.iter().all(|v| v.is_finite()) {
            Ok(x)
        } else {
            Err(Error::Singular(
                "ABD solve produced non-finite values".into(),
            ))
        }
    }

    /// Largest `|B_ij|` relative to `sqrt(max|A| · max|D|)`; ≈ 0 for symmetric layups.
    pub fn relative_coupling(&self) -> f64 {
        let amax = self.a.amax();
        let dmax = self.d.amax();
        let scale = (amax * dmax).sqrt();
        if scale > 0.0 {
            self.b.amax() / scale
        } else {
            0.0
        }
    }
}

/// Loads on a layup: applied resultants, a uniform temperature change and piezo voltages.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Loads {
    /// Applied force resultants `(Nx, Ny, Nxy)`, mN/mm.
    pub n: Vector3<f64>,
    /// Applied moment resultants `(Mx, My, Mxy)`, mN·mm/mm.
    pub m: Vector3<f64>,
    /// Uniform temperature change from the stress-free state, K (e.g. −180 K from a 200 °C cure
    /// to 20 °C).
    pub delta_t: f64,
    /// One voltage per **layer** (V), or empty for none; non-zero entries are allowed only on
    /// piezoelectric layers and apply to every piezo ply of the layer.
    pub voltages: Vec<f64>,
}

/// Mid-plane strains and curvatures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Response {
    /// Mid-plane strain `(εx, εy, γxy)`, dimensionless.
    pub strain: Vector3<f64>,
    /// Curvature `(κx, κy, κxy)`, 1/mm, (strain `ε(z) = ε0 + z κ`, `κx = −∂²w/∂x²`: positive
    /// κx stretches the top face, the layup bends concave towards −z).
    pub curvature: Vector3<f64>,
}

/// In-plane stress at the bottom and top faces of one ply, in laminate axes, mN/mm² (= kPa).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlyStress {
    /// Index of the layer (bottom = 0).
    pub layer: usize,
    /// Index of the ply within the layer.
    pub ply: usize,
    /// `z` of the ply bottom, mm.
    pub z_bottom: f64,
    /// `z` of the ply top, mm.
    pub z_top: f64,
    /// `(σx, σy, τxy)` at the bottom face, mN/mm².
    pub stress_bottom: Vector3<f64>,
    /// `(σx, σy, τxy)` at the top face, mN/mm².
    pub stress_top: Vector3<f64>,
}

/// A validated stack of named layers, listed bottom to top.
#[derive(Clone, Debug, PartialEq)]
pub struct Layup {
    layers: Vec<Layer>,
}

impl Layup {
    /// A layup from layers listed bottom to top; `Error::Geometry` if there are none.
    pub fn new(layers: Vec<Layer>) -> Result<Layup> {
        if layers.is_empty() {
            return Err(Error::Geometry("a layup needs at least one layer".into()));
        }
        Ok(Layup { layers })
    }

    /// A layup of single-ply layers given as `(name, material, thickness mm, angle rad)`.
    pub fn from_plies(plies: Vec<(String, Material, f64, f64)>) -> Result<Layup> {
        let layers = plies
            .into_iter()
            .enumerate()
            .map(|(i, (name, m, t, a))| {
                Layer::single(name, m, t, a).map_err(|e| e.in_field(&format!("layers[{i}]")))
            })
            .collect::<Result<Vec<_>>>()?;
        Layup::new(layers)
    }

    /// The stack mirrored about its top face: `[layers..., reversed layers...]` (symmetric).
    pub fn symmetric(layers: Vec<Layer>) -> Result<Layup> {
        let mut all = layers.clone();
        all.extend(layers.into_iter().rev().map(|mut l| {
            l.plies.reverse();
            l
        }));
        Layup::new(all)
    }

    /// Layers, bottom to top.
    pub fn layers(&self) -> &[Layer] {
        &self.layers
    }
    /// Number of named layers.
    pub fn len(&self) -> usize {
        self.layers.len()
    }
    /// Always `false` (a layup has at least one layer); provided for clippy's `len_without_is_empty`.
    pub fn is_empty(&self) -> bool {
        self.layers.is_empty()
    }
    /// Total thickness, mm.
    pub fn total_thickness(&self) -> f64 {
        self.layers.iter().map(Layer::thickness).sum()
    }
    /// Areal mass, mg/mm².
    pub fn areal_mass(&self) -> f64 {
        self.layers.iter().map(Layer::areal_mass).sum()
    }

    /// `(z_bottom, z_top)` of every layer about the mid-plane, mm.
    pub fn layer_bounds(&self) -> Vec<(f64, f64)> {
        let mut z = -0.5 * self.total_thickness();
        self.layers
            .iter()
            .map(|l| {
                let z0 = z;
                z += l.thickness();
                (z0, z)
            })
            .collect()
    }

    /// Every ply with its layer index, ply index and `(z_bottom, z_top)`, bottom to top.
    fn plies_with_z(&self) -> Vec<(usize, usize, &Ply, f64, f64)> {
        let mut z = -0.5 * self.total_thickness();
        let mut out = Vec::new();
        for (li, layer) in self.layers.iter().enumerate() {
            for (pi, ply) in layer.plies.iter().enumerate() {
                let z0 = z;
                z += ply.thickness;
                out.push((li, pi, ply, z0, z));
            }
        }
        out
    }

    /// The `ABD` matrix about the geometric mid-plane.
    pub fn abd(&self) -> Abd {
        let mut a = Matrix3::zeros();
        let mut b = Matrix3::zeros();
        let mut d = Matrix3::zeros();
        for (_, _, ply, z0, z1) in self.plies_with_z() {
            let q = ply.q_bar();
            a += q * (z1 - z0);
            b += q * (0.5 * (z1 * z1 - z0 * z0));
            d += q * ((z1 * z1 * z1 - z0 * z0 * z0) / 3.0);
        }
        Abd { a, b, d }
    }

    fn check_voltages(&self, voltages: &[f64]) -> Result<()> {
        if voltages.is_empty() {
            return Ok(());
        }
        if voltages.len() != self.layers.len() {
            return Err(Error::Shape(format!(
                "voltages has {} entries, the layup has {} layers",
                voltages.len(),
                self.layers.len()
            )));
        }
        for (i, (&v, layer)) in voltages.iter().zip(&self.layers).enumerate() {
            if !v.is_finite() {
                return Err(Error::invalid(
                    format!("voltages[{i}]"),
                    v,
                    "a finite number",
                ));
            }
            if v != 0.0 && !layer.is_piezo() {
                return Err(Error::invalid(
                    format!("voltages[{i}]"),
                    v,
                    format!("0 (layer `{}` is not piezoelectric)", layer.name),
                ));
            }
        }
        Ok(())
    }

    /// Free (thermal + piezoelectric) strain of each ply in laminate axes, in
    /// [`Layup::plies_with_z`] order.
    fn free_strains(&self, delta_t: f64, voltages: &[f64]) -> Vec<Vector3<f64>> {
        self.plies_with_z()
            .into_iter()
            .map(|(li, _, ply, _, _)| {
                let mut e = transformed_expansion(&ply.material, ply.angle) * delta_t;
                if let (Some(p), Some(&v)) = (ply.material.piezo(), voltages.get(li)) {
                    let s = p.d31 * v / ply.thickness;
                    e += Vector3::new(s, s, 0.0);
                }
                e
            })
            .collect()
    }

    /// Free (thermal + piezo) force and moment resultants `[N_free; M_free]` for a temperature
    /// change `delta_t` (K) and per-layer `voltages` (V, empty for none); mN/mm and mN.
    pub fn free_resultants(&self, delta_t: f64, voltages: &[f64]) -> Result<Vector6<f64>> {
        check_finite("delta_t", delta_t)?;
        self.check_voltages(voltages)?;
        let strains = self.free_strains(delta_t, voltages);
        let mut r = Vector6::zeros();
        for ((_, _, ply, z0, z1), e) in self.plies_with_z().into_iter().zip(strains) {
            let qe = ply.q_bar() * e;
            r.fixed_rows_mut::<3>(0).add_assign(qe * (z1 - z0));
            r.fixed_rows_mut::<3>(3)
                .add_assign(qe * (0.5 * (z1 * z1 - z0 * z0)));
        }
        Ok(r)
    }

    /// Mid-plane strains and curvatures under `loads`: `[ε0; κ] = ABD⁻¹ ([N; M] + free)`.
    pub fn response(&self, loads: &Loads) -> Result<Response> {
        for i in 0..3 {
            check_finite("n", loads.n[i])?;
            check_finite("m", loads.m[i])?;
        }
        let mut rhs = self.free_resultants(loads.delta_t, &loads.voltages)?;
        rhs.fixed_rows_mut::<3>(0).add_assign(loads.n);
        rhs.fixed_rows_mut::<3>(3).add_assign(loads.m);
        let x = self.abd().solve(&rhs)?;
        Ok(Response {
            strain: x.fixed_rows::<3>(0).into_owned(),
            curvature: x.fixed_rows::<3>(3).into_owned(),
        })
    }

    /// Curvature `(κx, κy, κxy)` (1/mm) of the free layup after a uniform temperature change
    /// `delta_t` (K) from its stress-free state. Zero for symmetric layups.
    ///
    /// Cure example (§4.5.3): laminated at 200 °C, used at 20 °C, `delta_t = −180` K
    /// ([`crate::pcmems::CURE_DELTA_T`]). Assumes linear elasticity with temperature-independent
    /// properties and a stress-free state at the cure temperature.
    pub fn thermal_curvature(&self, delta_t: f64) -> Result<Vector3<f64>> {
        Ok(self
            .response(&Loads {
                delta_t,
                ..Loads::default()
            })?
            .curvature)
    }

    /// Stresses at the faces of every ply under `loads` (laminate axes):
    /// `σ = Q̄ (ε0 + z κ − ε_free)`, mN/mm².
    pub fn ply_stresses(&self, loads: &Loads) -> Result<Vec<PlyStress>> {
        let r = self.response(loads)?;
        let strains = self.free_strains(loads.delta_t, &loads.voltages);
        Ok(self
            .plies_with_z()
            .into_iter()
            .zip(strains)
            .map(|((li, pi, ply, z0, z1), ef)| {
                let q = ply.q_bar();
                PlyStress {
                    layer: li,
                    ply: pi,
                    z_bottom: z0,
                    z_top: z1,
                    stress_bottom: q * (r.strain + r.curvature * z0 - ef),
                    stress_top: q * (r.strain + r.curvature * z1 - ef),
                }
            })
            .collect())
    }

    /// Beam bending stiffness per unit width along x, `1 / d11` with `d = D*⁻¹` of the full
    /// compliance (narrow-beam assumption: `My = Mxy = 0`, `N = 0`), mN·mm (= mN·mm²/mm).
    pub fn beam_bending_stiffness(&self) -> Result<f64> {
        let c = self.abd().compliance()?;
        Ok(1.0 / c[(3, 3)])
    }

    /// Effective in-plane Young's modulus along x, `1 / (h a11)`, mN/mm².
    pub fn effective_modulus_x(&self) -> Result<f64> {
        let c = self.abd().compliance()?;
        Ok(1.0 / (self.total_thickness() * c[(0, 0)]))
    }

    /// `true` if the stacking is mirror-symmetric about the mid-plane (same materials, angles and
    /// thicknesses of the plies at mirrored positions, to 1e-12 relative in thickness).
    pub fn is_symmetric(&self) -> bool {
        let plies: Vec<&Ply> = self.layers.iter().flat_map(|l| l.plies.iter()).collect();
        let n = plies.len();
        (0..n / 2).all(|i| {
            let (p, q) = (plies[i], plies[n - 1 - i]);
            p.material == q.material
                && (p.angle - q.angle).abs() <= 1e-12
                && (p.thickness - q.thickness).abs() <= 1e-12 * p.thickness.max(q.thickness)
        })
    }
}
