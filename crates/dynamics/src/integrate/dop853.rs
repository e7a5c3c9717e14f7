//! Dormand–Prince 8(5,3) with Hairer's 7th-order continuous extension (CONTD8).
//!
//! Coefficients and the error estimate follow `dop853.f` (E. Hairer, G. Wanner, version of
//! 2004; Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.10). The interpolant is
//! `y(t + s h) = r1 + s (r2 + s' (r3 + s (r4 + s' (r5 + s (r6 + s' (r7 + s r8))))))` with
//! `s' = 1 − s`: the alternation starts with `s'` at `r3` and continues through the
//! higher-order part (`r5` multiplied by `s'`, `r6` by `s`, …). Getting this alternation wrong
//! (as `differential-equations` 0.7.0 does) degrades the interpolant to O(h⁵).

// Coefficients as printed in dop853.f (30 digits; rounded to f64 by the compiler).
#![allow(clippy::excessive_precision)]

use super::{Rhs, Stepper, Tolerances};
use paritysim_error::Result;
use paritysim_simd::Real;

// The SIMD-lane ensemble version shares this file's coefficients (child modules see them).
#[path = "dop853_lanes.rs"]
pub(crate) mod lanes;

const C2: f64 = 0.526001519587677318785587544488E-01;
const C3: f64 = 0.789002279381515978178381316732E-01;
const C4: f64 = 0.118350341907227396726757197510E+00;
const C5: f64 = 0.281649658092772603273242802490E+00;
const C6: f64 = 0.333333333333333333333333333333E+00;
const C7: f64 = 0.25E+00;
const C8: f64 = 0.307692307692307692307692307692E+00;
const C9: f64 = 0.651282051282051282051282051282E+00;
const C10: f64 = 0.6E+00;
const C11: f64 = 0.857142857142857142857142857142E+00;
const C14: f64 = 0.1E+00;
const C15: f64 = 0.2E+00;
const C16: f64 = 0.777777777777777777777777777778E+00;

const B1: f64 = 5.42937341165687622380535766363E-2;
const B6: f64 = 4.45031289275240888144113950566E0;
const B7: f64 = 1.89151789931450038304281599044E0;
const B8: f64 = -5.8012039600105847814672114227E0;
const B9: f64 = 3.1116436695781989440891606237E-1;
const B10: f64 = -1.52160949662516078556178806805E-1;
const B11: f64 = 2.01365400804030348374776537501E-1;
const B12: f64 = 4.47106157277725905176885569043E-2;

const BHH1: f64 = 0.244094488188976377952755905512E+00;
const BHH2: f64 = 0.733846688281611857341361741547E+00;
const BHH3: f64 = 0.220588235294117647058823529412E-01;

const ER1: f64 = 0.1312004499419488073250102996E-01;
const ER6: f64 = -0.1225156446376204440720569753E+01;
const ER7: f64 = -0.4957589496572501915214079952E+00;
const ER8: f64 = 0.1664377182454986536961530415E+01;
const ER9: f64 = -0.3503288487499736816886487290E+00;
const ER10: f64 = 0.3341791187130174790297318841E+00;
const ER11: f64 = 0.8192320648511571246570742613E-01;
const ER12: f64 = -0.2235530786388629525884427845E-01;

const A21: f64 = 5.26001519587677318785587544488E-2;
const A31: f64 = 1.97250569845378994544595329183E-2;
const A32: f64 = 5.91751709536136983633785987549E-2;
const A41: f64 = 2.95875854768068491816892993775E-2;
const A43: f64 = 8.87627564304205475450678981324E-2;
const A51: f64 = 2.41365134159266685502369798665E-1;
const A53: f64 = -8.84549479328286085344864962717E-1;
const A54: f64 = 9.24834003261792003115737966543E-1;
const A61: f64 = 3.7037037037037037037037037037E-2;
const A64: f64 = 1.70828608729473871279604482173E-1;
const A65: f64 = 1.25467687566822425016691814123E-1;
const A71: f64 = 3.7109375E-2;
const A74: f64 = 1.70252211019544039314978060272E-1;
const A75: f64 = 6.02165389804559606850219397283E-2;
const A76: f64 = -1.7578125E-2;
const A81: f64 = 3.70920001185047927108779319836E-2;
const A84: f64 = 1.70383925712239993810214054705E-1;
const A85: f64 = 1.07262030446373284651809199168E-1;
const A86: f64 = -1.53194377486244017527936158236E-2;
const A87: f64 = 8.27378916381402288758473766002E-3;
const A91: f64 = 6.24110958716075717114429577812E-1;
const A94: f64 = -3.36089262944694129406857109825E0;
const A95: f64 = -8.68219346841726006818189891453E-1;
const A96: f64 = 2.75920996994467083049415600797E1;
const A97: f64 = 2.01540675504778934086186788979E1;
const A98: f64 = -4.34898841810699588477366255144E1;
const A101: f64 = 4.77662536438264365890433908527E-1;
const A104: f64 = -2.48811461997166764192642586468E0;
const A105: f64 = -5.90290826836842996371446475743E-1;
const A106: f64 = 2.12300514481811942347288949897E1;
const A107: f64 = 1.52792336328824235832596922938E1;
const A108: f64 = -3.32882109689848629194453265587E1;
const A109: f64 = -2.03312017085086261358222928593E-2;
const A111: f64 = -9.3714243008598732571704021658E-1;
const A114: f64 = 5.18637242884406370830023853209E0;
const A115: f64 = 1.09143734899672957818500254654E0;
const A116: f64 = -8.14978701074692612513997267357E0;
const A117: f64 = -1.85200656599969598641566180701E1;
const A118: f64 = 2.27394870993505042818970056734E1;
const A119: f64 = 2.49360555267965238987089396762E0;
const A1110: f64 = -3.0467644718982195003823669022E0;
const A121: f64 = 2.27331014751653820792359768449E0;
const A124: f64 = -1.05344954667372501984066689879E1;
const A125: f64 = -2.00087205822486249909675718444E0;
const A126: f64 = -1.79589318631187989172765950534E1;
const A127: f64 = 2.79488845294199600508499808837E1;
const A128: f64 = -2.85899827713502369474065508674E0;
const A129: f64 = -8.87285693353062954433549289258E0;
const A1210: f64 = 1.23605671757943030647266201528E1;
const A1211: f64 = 6.43392746015763530355970484046E-1;

const A141: f64 = 5.61675022830479523392909219681E-2;
const A147: f64 = 2.53500210216624811088794765333E-1;
const A148: f64 = -2.46239037470802489917441475441E-1;
const A149: f64 = -1.24191423263816360469010140626E-1;
const A1410: f64 = 1.5329179827876569731206322685E-1;
const A1411: f64 = 8.20105229563468988491666602057E-3;
const A1412: f64 = 7.56789766054569976138603589584E-3;
const A1413: f64 = -8.298E-3;

const A151: f64 = 3.18346481635021405060768473261E-2;
const A156: f64 = 2.83009096723667755288322961402E-2;
const A157: f64 = 5.35419883074385676223797384372E-2;
const A158: f64 = -5.49237485713909884646569340306E-2;
const A1511: f64 = -1.08347328697249322858509316994E-4;
const A1512: f64 = 3.82571090835658412954920192323E-4;
const A1513: f64 = -3.40465008687404560802977114492E-4;
const A1514: f64 = 1.41312443674632500278074618366E-1;
const A161: f64 = -4.28896301583791923408573538692E-1;
const A166: f64 = -4.69762141536116384314449447206E0;
const A167: f64 = 7.68342119606259904184240953878E0;
const A168: f64 = 4.06898981839711007970213554331E0;
const A169: f64 = 3.56727187455281109270669543021E-1;
const A1613: f64 = -1.39902416515901462129418009734E-3;
const A1614: f64 = 2.9475147891527723389556272149E0;
const A1615: f64 = -9.15095847217987001081870187138E0;

const D41: f64 = -0.84289382761090128651353491142E+01;
const D46: f64 = 0.56671495351937776962531783590E+00;
const D47: f64 = -0.30689499459498916912797304727E+01;
const D48: f64 = 0.23846676565120698287728149680E+01;
const D49: f64 = 0.21170345824450282767155149946E+01;
const D410: f64 = -0.87139158377797299206789907490E+00;
const D411: f64 = 0.22404374302607882758541771650E+01;
const D412: f64 = 0.63157877876946881815570249290E+00;
const D413: f64 = -0.88990336451333310820698117400E-01;
const D414: f64 = 0.18148505520854727256656404962E+02;
const D415: f64 = -0.91946323924783554000451984436E+01;
const D416: f64 = -0.44360363875948939664310572000E+01;
const D51: f64 = 0.10427508642579134603413151009E+02;
const D56: f64 = 0.24228349177525818288430175319E+03;
const D57: f64 = 0.16520045171727028198505394887E+03;
const D58: f64 = -0.37454675472269020279518312152E+03;
const D59: f64 = -0.22113666853125306036270938578E+02;
const D510: f64 = 0.77334326684722638389603898808E+01;
const D511: f64 = -0.30674084731089398182061213626E+02;
const D512: f64 = -0.93321305264302278729567221706E+01;
const D513: f64 = 0.15697238121770843886131091075E+02;
const D514: f64 = -0.31139403219565177677282850411E+02;
const D515: f64 = -0.93529243588444783865713862664E+01;
const D516: f64 = 0.35816841486394083752465898540E+02;
const D61: f64 = 0.19985053242002433820987653617E+02;
const D66: f64 = -0.38703730874935176555105901742E+03;
const D67: f64 = -0.18917813819516756882830838328E+03;
const D68: f64 = 0.52780815920542364900561016686E+03;
const D69: f64 = -0.11573902539959630126141871134E+02;
const D610: f64 = 0.68812326946963000169666922661E+01;
const D611: f64 = -0.10006050966910838403183860980E+01;
const D612: f64 = 0.77771377980534432092869265740E+00;
const D613: f64 = -0.27782057523535084065932004339E+01;
const D614: f64 = -0.60196695231264120758267380846E+02;
const D615: f64 = 0.84320405506677161018159903784E+02;
const D616: f64 = 0.11992291136182789328035130030E+02;
const D71: f64 = -0.25693933462703749003312586129E+02;
const D76: f64 = -0.15418974869023643374053993627E+03;
const D77: f64 = -0.23152937917604549567536039109E+03;
const D78: f64 = 0.35763911791061412378285349910E+03;
const D79: f64 = 0.93405324183624310003907691704E+02;
const D710: f64 = -0.37458323136451633156875139351E+02;
const D711: f64 = 0.10409964950896230045147246184E+03;
const D712: f64 = 0.29840293426660503123344363579E+02;
const D713: f64 = -0.43533456590011143754432175058E+02;
const D714: f64 = 0.96324553959188282948394950600E+02;
const D715: f64 = -0.39177261675615439165231486172E+02;
const D716: f64 = -0.14972683625798562581422125276E+03;

/// One DOP853 step on `M` entries of any number type: `f64` (the scalar stepper) or one
/// problem per SIMD lane (`lanes`), so both run the same operations in the same order and a
/// lane is bit-identical to the scalar integration of its problem.
pub(crate) struct Dop853<const M: usize, S = f64> {
    k: [[S; M]; 10],
    pub(crate) y1: [S; M],
    pub(crate) cont: [[S; M]; 8],
}

/// `y + h Σ aᵢ kᵢ` written once per stage (the compiler keeps the loop over `M` tight).
macro_rules! stage {
    ($out:expr, $y:expr, $h:expr, $( $a:expr => $k:expr ),+ ) => {
        for i in 0..M {
            $out[i] = $y[i] + $h * (S::splat(0.0) $( + S::splat($a) * $k[i] )+);
        }
    };
}

/// `Σ cᵢ kᵢ[i]`, left to right (the increment, error and dense-output sums), optionally
/// added to a first term.
macro_rules! sum {
    ($i:expr; $first:expr $(, $c:expr => $k:expr )+ ) => {
        $first $( + S::splat($c) * $k[$i] )+
    };
    ($i:expr, $c0:expr => $k0:expr $(, $c:expr => $k:expr )* ) => {
        S::splat($c0) * $k0[$i] $( + S::splat($c) * $k[$i] )*
    };
}

impl<const M: usize, S: Real> Dop853<M, S> {
    pub(crate) fn new() -> Self {
        let z = [S::splat(0.0); M];
        Self {
            k: [z; 10],
            y1: z,
            cont: [z; 8],
        }
    }

    /// The step from `y` (`f0 = f(t, y)`) by `h`: its stages, `y1`, and the error norm over
    /// the first `controlled` entries. `eval(stage, c, y, f)` writes `f(t + c h, y)` of
    /// stage 1..=11 (its position in the step, for right-hand sides that tabulate time).
    pub(crate) fn try_step<E>(
        &mut self,
        y: &[S; M],
        f0: &[S; M],
        h: S,
        (controlled, atol, rtol): (usize, S, S),
        mut eval: impl FnMut(usize, f64, &[S; M], &mut [S; M]) -> std::result::Result<(), E>,
    ) -> std::result::Result<S, E> {
        // Hairer's storage names (k1 = f0; k2, k3 hold stages 11, 12 at the end).
        let [k2, k3, k4, k5, k6, k7, k8, k9, k10, _] = &mut self.k;
        let k1 = f0;
        let mut ys = [S::splat(0.0); M];
        stage!(ys, y, h, A21 => k1);
        eval(1, C2, &ys, k2)?;
        stage!(ys, y, h, A31 => k1, A32 => k2);
        eval(2, C3, &ys, k3)?;
        stage!(ys, y, h, A41 => k1, A43 => k3);
        eval(3, C4, &ys, k4)?;
        stage!(ys, y, h, A51 => k1, A53 => k3, A54 => k4);
        eval(4, C5, &ys, k5)?;
        stage!(ys, y, h, A61 => k1, A64 => k4, A65 => k5);
        eval(5, C6, &ys, k6)?;
        stage!(ys, y, h, A71 => k1, A74 => k4, A75 => k5, A76 => k6);
        eval(6, C7, &ys, k7)?;
        stage!(ys, y, h, A81 => k1, A84 => k4, A85 => k5, A86 => k6, A87 => k7);
        eval(7, C8, &ys, k8)?;
        stage!(ys, y, h, A91 => k1, A94 => k4, A95 => k5, A96 => k6, A97 => k7, A98 => k8);
        eval(8, C9, &ys, k9)?;
        stage!(ys, y, h, A101 => k1, A104 => k4, A105 => k5, A106 => k6, A107 => k7, A108 => k8,
            A109 => k9);
        eval(9, C10, &ys, k10)?;
        stage!(ys, y, h, A111 => k1, A114 => k4, A115 => k5, A116 => k6, A117 => k7, A118 => k8,
            A119 => k9, A1110 => k10);
        eval(10, C11, &ys, k2)?;
        stage!(ys, y, h, A121 => k1, A124 => k4, A125 => k5, A126 => k6, A127 => k7, A128 => k8,
            A129 => k9, A1210 => k10, A1211 => k2);
        eval(11, 1.0, &ys, k3)?;
        // The 8th-order increment gives y1; the 5th- and 3rd-order estimates its error.
        let mut err5 = S::splat(0.0);
        let mut err3 = S::splat(0.0);
        for i in 0..M {
            let inc = sum!(i, B1 => k1, B6 => k6, B7 => k7, B8 => k8, B9 => k9, B10 => k10,
                B11 => k2, B12 => k3);
            let y1 = y[i] + h * inc;
            self.y1[i] = y1;
            if i < controlled {
                let sk = atol + rtol * y[i].abs().max(y1.abs());
                let e3 =
                    inc - S::splat(BHH1) * k1[i] - S::splat(BHH2) * k9[i] - S::splat(BHH3) * k3[i];
                let e5 = sum!(i, ER1 => k1, ER6 => k6, ER7 => k7, ER8 => k8, ER9 => k9,
                    ER10 => k10, ER11 => k2, ER12 => k3);
                err3 = err3 + (e3 / sk) * (e3 / sk);
                err5 = err5 + (e5 / sk) * (e5 / sk);
            }
        }
        let deno = err5 + S::splat(0.01) * err3;
        let deno = S::select(deno.le(S::splat(0.0)), S::splat(1.0), deno);
        Ok(h.abs() * err5 * (S::splat(1.0) / (S::splat(controlled as f64) * deno)).sqrt())
    }

    /// The dense output of the step just taken (`f1 = f(t + h, y1)`); `eval` as in
    /// [`Self::try_step`], stages 12..=14.
    pub(crate) fn dense_output<E>(
        &mut self,
        y: &[S; M],
        f0: &[S; M],
        f1: &[S; M],
        h: S,
        mut eval: impl FnMut(usize, f64, &[S; M], &mut [S; M]) -> std::result::Result<(), E>,
    ) -> std::result::Result<(), E> {
        let [k2, k3, _k4, _k5, k6, k7, k8, k9, k10, kx] = &mut self.k;
        let k1 = f0;
        let k13 = f1;
        let [r1, r2, r3, r4, r5, r6, r7, r8] = &mut self.cont;
        for i in 0..M {
            let ydiff = self.y1[i] - y[i];
            let bspl = h * k1[i] - ydiff;
            r1[i] = y[i];
            r2[i] = ydiff;
            r3[i] = bspl;
            r4[i] = ydiff - h * k13[i] - bspl;
            r5[i] = sum!(i, D41 => k1, D46 => k6, D47 => k7, D48 => k8, D49 => k9, D410 => k10,
                D411 => k2, D412 => k3);
            r6[i] = sum!(i, D51 => k1, D56 => k6, D57 => k7, D58 => k8, D59 => k9, D510 => k10,
                D511 => k2, D512 => k3);
            r7[i] = sum!(i, D61 => k1, D66 => k6, D67 => k7, D68 => k8, D69 => k9, D610 => k10,
                D611 => k2, D612 => k3);
            r8[i] = sum!(i, D71 => k1, D76 => k6, D77 => k7, D78 => k8, D79 => k9, D710 => k10,
                D711 => k2, D712 => k3);
        }
        // The three extra stages (14, 15, 16); k10 and k2/k3 are still needed, so 14 goes to the
        // spare slot, 15 and 16 reuse slots whose stages are already folded into r5..r8.
        let mut ys = [S::splat(0.0); M];
        stage!(ys, y, h, A141 => k1, A147 => k7, A148 => k8, A149 => k9, A1410 => k10,
            A1411 => k2, A1412 => k3, A1413 => k13);
        eval(12, C14, &ys, kx)?;
        let k14 = *kx;
        stage!(ys, y, h, A151 => k1, A156 => k6, A157 => k7, A158 => k8, A1511 => k2,
            A1512 => k3, A1513 => k13, A1514 => &k14);
        eval(13, C15, &ys, k10)?;
        let k15 = *k10;
        stage!(ys, y, h, A161 => k1, A166 => k6, A167 => k7, A168 => k8, A169 => k9,
            A1613 => k13, A1614 => &k14, A1615 => &k15);
        eval(14, C16, &ys, k2)?;
        let k16 = &*k2;
        for i in 0..M {
            r5[i] = h * sum!(i; r5[i], D413 => k13, D414 => k14, D415 => k15, D416 => k16);
            r6[i] = h * sum!(i; r6[i], D513 => k13, D514 => k14, D515 => k15, D516 => k16);
            r7[i] = h * sum!(i; r7[i], D613 => k13, D614 => k14, D615 => k15, D616 => k16);
            r8[i] = h * sum!(i; r8[i], D713 => k13, D714 => k14, D715 => k15, D716 => k16);
        }
        Ok(())
    }
}

/// The interpolant at `s ∈ [0, 1]` of the step, from one entry's coefficients `r1..r8`.
#[inline]
pub(crate) fn interpolate<S: Real>(r: [S; 8], s: S) -> S {
    let s1 = S::splat(1.0) - s;
    r[0] + s * (r[1] + s1 * (r[2] + s * (r[3] + s1 * (r[4] + s * (r[5] + s1 * (r[6] + s * r[7]))))))
}

impl<const M: usize> Stepper<M> for Dop853<M> {
    const ORDER: i32 = 8;
    const EXPONENT: f64 = 1.0 / 8.0;
    const BETA: f64 = 0.0;
    const FAC_MIN: f64 = 0.333;
    const FAC_MAX: f64 = 6.0;

    fn attempt(
        &mut self,
        rhs: &mut dyn Rhs<M>,
        t: f64,
        y: &[f64; M],
        f0: &[f64; M],
        h: f64,
        tol: &Tolerances,
    ) -> Result<f64> {
        let tol = (tol.controlled, tol.atol, tol.rtol);
        self.try_step(y, f0, h, tol, |_, c, ys, f| rhs.eval(t + c * h, ys, f))
    }

    fn y1(&self) -> &[f64; M] {
        &self.y1
    }

    fn new_derivative(
        &mut self,
        rhs: &mut dyn Rhs<M>,
        t_new: f64,
        f1: &mut [f64; M],
    ) -> Result<()> {
        rhs.eval(t_new, &self.y1, f1)
    }

    fn prepare_dense(
        &mut self,
        rhs: &mut dyn Rhs<M>,
        t: f64,
        y: &[f64; M],
        f0: &[f64; M],
        f1: &[f64; M],
        h: f64,
    ) -> Result<()> {
        self.dense_output(y, f0, f1, h, |_, c, ys, f| rhs.eval(t + c * h, ys, f))
    }

    fn dense(&self, s: f64, out: &mut [f64; M]) {
        for (i, out) in out.iter_mut().enumerate() {
            *out = interpolate(std::array::from_fn(|r| self.cont[r][i]), s);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coefficients_match_differential_equations_tableau() {
        let t = differential_equations::tableau::ButcherTableau::<f64, 12, 16>::dop853();
        let (bh, er, bi) = (t.bh.unwrap(), t.er.unwrap(), t.bi.unwrap());
        for (ours, theirs, name) in [
            (C2, t.c[1], "C2"),
            (C3, t.c[2], "C3"),
            (C4, t.c[3], "C4"),
            (C5, t.c[4], "C5"),
            (C6, t.c[5], "C6"),
            (C7, t.c[6], "C7"),
            (C8, t.c[7], "C8"),
            (C9, t.c[8], "C9"),
            (C10, t.c[9], "C10"),
            (C11, t.c[10], "C11"),
            (C14, t.c[13], "C14"),
            (C15, t.c[14], "C15"),
            (C16, t.c[15], "C16"),
            (B1, t.b[0], "B1"),
            (B6, t.b[5], "B6"),
            (B7, t.b[6], "B7"),
            (B8, t.b[7], "B8"),
            (B9, t.b[8], "B9"),
            (B10, t.b[9], "B10"),
            (B11, t.b[10], "B11"),
            (B12, t.b[11], "B12"),
            (BHH1, bh[0], "BHH1"),
            (BHH2, bh[8], "BHH2"),
            (BHH3, bh[11], "BHH3"),
            (ER1, er[0], "ER1"),
            (ER6, er[5], "ER6"),
            (ER7, er[6], "ER7"),
            (ER8, er[7], "ER8"),
            (ER9, er[8], "ER9"),
            (ER10, er[9], "ER10"),
            (ER11, er[10], "ER11"),
            (ER12, er[11], "ER12"),
            (A21, t.a[1][0], "A21"),
            (A31, t.a[2][0], "A31"),
            (A32, t.a[2][1], "A32"),
            (A41, t.a[3][0], "A41"),
            (A43, t.a[3][2], "A43"),
            (A51, t.a[4][0], "A51"),
            (A53, t.a[4][2], "A53"),
            (A54, t.a[4][3], "A54"),
            (A61, t.a[5][0], "A61"),
            (A64, t.a[5][3], "A64"),
            (A65, t.a[5][4], "A65"),
            (A71, t.a[6][0], "A71"),
            (A74, t.a[6][3], "A74"),
            (A75, t.a[6][4], "A75"),
            (A76, t.a[6][5], "A76"),
            (A81, t.a[7][0], "A81"),
            (A84, t.a[7][3], "A84"),
            (A85, t.a[7][4], "A85"),
            (A86, t.a[7][5], "A86"),
            (A87, t.a[7][6], "A87"),
            (A91, t.a[8][0], "A91"),
            (A94, t.a[8][3], "A94"),
            (A95, t.a[8][4], "A95"),
            (A96, t.a[8][5], "A96"),
            (A97, t.a[8][6], "A97"),
            (A98, t.a[8][7], "A98"),
            (A101, t.a[9][0], "A101"),
            (A104, t.a[9][3], "A104"),
            (A105, t.a[9][4], "A105"),
            (A106, t.a[9][5], "A106"),
            (A107, t.a[9][6], "A107"),
            (A108, t.a[9][7], "A108"),
            (A109, t.a[9][8], "A109"),
            (A111, t.a[10][0], "A111"),
            (A114, t.a[10][3], "A114"),
            (A115, t.a[10][4], "A115"),
            (A116, t.a[10][5], "A116"),
            (A117, t.a[10][6], "A117"),
            (A118, t.a[10][7], "A118"),
            (A119, t.a[10][8], "A119"),
            (A1110, t.a[10][9], "A1110"),
            (A121, t.a[11][0], "A121"),
            (A124, t.a[11][3], "A124"),
            (A125, t.a[11][4], "A125"),
            (A126, t.a[11][5], "A126"),
            (A127, t.a[11][6], "A127"),
            (A128, t.a[11][7], "A128"),
            (A129, t.a[11][8], "A129"),
            (A1210, t.a[11][9], "A1210"),
            (A1211, t.a[11][10], "A1211"),
            (A141, t.a[13][0], "A141"),
            (A147, t.a[13][6], "A147"),
            (A148, t.a[13][7], "A148"),
            (A149, t.a[13][8], "A149"),
            (A1410, t.a[13][9], "A1410"),
            (A1411, t.a[13][10], "A1411"),
            (A1412, t.a[13][11], "A1412"),
            (A1413, t.a[13][12], "A1413"),
            (A151, t.a[14][0], "A151"),
            (A156, t.a[14][5], "A156"),
            (A157, t.a[14][6], "A157"),
            (A158, t.a[14][7], "A158"),
            (A1511, t.a[14][10], "A1511"),
            (A1512, t.a[14][11], "A1512"),
            (A1513, t.a[14][12], "A1513"),
            (A1514, t.a[14][13], "A1514"),
            (A161, t.a[15][0], "A161"),
            (A166, t.a[15][5], "A166"),
            (A167, t.a[15][6], "A167"),
            (A168, t.a[15][7], "A168"),
            (A169, t.a[15][8], "A169"),
            (A1613, t.a[15][12], "A1613"),
            (A1614, t.a[15][13], "A1614"),
            (A1615, t.a[15][14], "A1615"),
            (D41, bi[4][0], "D41"),
            (D46, bi[4][5], "D46"),
            (D47, bi[4][6], "D47"),
            (D48, bi[4][7], "D48"),
            (D49, bi[4][8], "D49"),
            (D410, bi[4][9], "D410"),
            (D411, bi[4][10], "D411"),
            (D412, bi[4][11], "D412"),
            (D413, bi[4][12], "D413"),
            (D414, bi[4][13], "D414"),
            (D415, bi[4][14], "D415"),
            (D416, bi[4][15], "D416"),
            (D51, bi[5][0], "D51"),
            (D56, bi[5][5], "D56"),
            (D57, bi[5][6], "D57"),
            (D58, bi[5][7], "D58"),
            (D59, bi[5][8], "D59"),
            (D510, bi[5][9], "D510"),
            (D511, bi[5][10], "D511"),
            (D512, bi[5][11], "D512"),
            (D513, bi[5][12], "D513"),
            (D514, bi[5][13], "D514"),
            (D515, bi[5][14], "D515"),
            (D516, bi[5][15], "D516"),
            (D61, bi[6][0], "D61"),
            (D66, bi[6][5], "D66"),
            (D67, bi[6][6], "D67"),
            (D68, bi[6][7], "D68"),
            (D69, bi[6][8], "D69"),
            (D610, bi[6][9], "D610"),
            (D611, bi[6][10], "D611"),
            (D612, bi[6][11], "D612"),
            (D613, bi[6][12], "D613"),
            (D614, bi[6][13], "D614"),
            (D615, bi[6][14], "D615"),
            (D616, bi[6][15], "D616"),
            (D71, bi[7][0], "D71"),
            (D76, bi[7][5], "D76"),
            (D77, bi[7][6], "D77"),
            (D78, bi[7][7], "D78"),
            (D79, bi[7][8], "D79"),
            (D710, bi[7][9], "D710"),
            (D711, bi[7][10], "D711"),
            (D712, bi[7][11], "D712"),
            (D713, bi[7][12], "D713"),
            (D714, bi[7][13], "D714"),
            (D715, bi[7][14], "D715"),
            (D716, bi[7][15], "D716"),
        ] {
            assert!(
                (ours - theirs).abs() <= 4e-16 * ours.abs().max(1.0),
                "{name}: {ours} vs {theirs}"
            );
        }
    }
}
