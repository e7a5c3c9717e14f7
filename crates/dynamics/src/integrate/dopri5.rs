//! Dormand–Prince 5(4) with Hairer's 4th-order continuous extension (CONTD5, `dopri5.f`).
//!
//! `y(t + s h) = r1 + s (r2 + s' (r3 + s (r4 + s' r5)))`, `s' = 1 − s`; no extra stages (the
//! seventh stage is the derivative at the new point, reused as the next step's first: FSAL).

use super::{Rhs, Stepper, Tolerances};
use paritysim_error::Result;

const C2: f64 = 0.2;
const C3: f64 = 0.3;
const C4: f64 = 0.8;
const C5: f64 = 8.0 / 9.0;
const A21: f64 = 0.2;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
const A71: f64 = 35.0 / 384.0;
const A73: f64 = 500.0 / 1113.0;
const A74: f64 = 125.0 / 192.0;
const A75: f64 = -2187.0 / 6784.0;
const A76: f64 = 11.0 / 84.0;
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;
const D1: f64 = -12715105075.0 / 11282082432.0;
const D3: f64 = 87487479700.0 / 32700410799.0;
const D4: f64 = -10690763975.0 / 1880347072.0;
const D5: f64 = 701980252875.0 / 199316789632.0;
const D6: f64 = -1453857185.0 / 822651844.0;
const D7: f64 = 69997945.0 / 29380423.0;

/// Stage storage of one DOPRI5 step on a state of `M` entries.
pub(crate) struct Dopri5<const M: usize> {
    k: [[f64; M]; 6],
    y1: [f64; M],
    cont: [[f64; M]; 5],
}

impl<const M: usize> Dopri5<M> {
    pub(crate) fn new() -> Self {
        Self {
            k: [[0.0; M]; 6],
            y1: [0.0; M],
            cont: [[0.0; M]; 5],
        }
    }
}

impl<const M: usize> Stepper<M> for Dopri5<M> {
    const ORDER: i32 = 5;
    const EXPONENT: f64 = 0.2 - Self::BETA * 0.75;
    const BETA: f64 = 0.04;
    const FAC_MIN: f64 = 0.2;
    const FAC_MAX: f64 = 10.0;

    fn attempt(
        &mut self,
        rhs: &mut dyn Rhs<M>,
        t: f64,
        y: &[f64; M],
        f0: &[f64; M],
        h: f64,
        tol: &Tolerances,
    ) -> Result<f64> {
        let [k2, k3, k4, k5, k6, k7] = &mut self.k;
        let k1 = f0;
        let mut ys = [0.0; M];
        for i in 0..M {
            ys[i] = y[i] + h * A21 * k1[i];
        }
        rhs.eval(t + C2 * h, &ys, k2)?;
        for i in 0..M {
            ys[i] = y[i] + h * (A31 * k1[i] + A32 * k2[i]);
        }
        rhs.eval(t + C3 * h, &ys, k3)?;
        for i in 0..M {
            ys[i] = y[i] + h * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i]);
        }
        rhs.eval(t + C4 * h, &ys, k4)?;
        for i in 0..M {
            ys[i] = y[i] + h * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i]);
        }
        rhs.eval(t + C5 * h, &ys, k5)?;
        for i in 0..M {
            ys[i] =
                y[i] + h * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i]);
        }
        rhs.eval(t + h, &ys, k6)?;
        for i in 0..M {
            self.y1[i] =
                y[i] + h * (A71 * k1[i] + A73 * k3[i] + A74 * k4[i] + A75 * k5[i] + A76 * k6[i]);
        }
        rhs.eval(t + h, &self.y1, k7)?;
        let mut err = 0.0;
        for i in 0..tol.controlled {
            let e =
                h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i]);
            let sk = tol.atol + tol.rtol * y[i].abs().max(self.y1[i].abs());
            err += (e / sk) * (e / sk);
        }
        Ok((err / tol.controlled as f64).sqrt())
    }

    fn y1(&self) -> &[f64; M] {
        &self.y1
    }

    fn new_derivative(
        &mut self,
        _rhs: &mut dyn Rhs<M>,
        _t_new: f64,
        f1: &mut [f64; M],
    ) -> Result<()> {
        *f1 = self.k[5];
        Ok(())
    }

    fn prepare_dense(
        &mut self,
        _rhs: &mut dyn Rhs<M>,
        _t: f64,
        y: &[f64; M],
        f0: &[f64; M],
        f1: &[f64; M],
        h: f64,
    ) -> Result<()> {
        let [_k2, k3, k4, k5, k6, _k7] = &self.k;
        let [r1, r2, r3, r4, r5] = &mut self.cont;
        for i in 0..M {
            let ydiff = self.y1[i] - y[i];
            let bspl = h * f0[i] - ydiff;
            r1[i] = y[i];
            r2[i] = ydiff;
            r3[i] = bspl;
            r4[i] = ydiff - h * f1[i] - bspl;
            r5[i] =
                h * (D1 * f0[i] + D3 * k3[i] + D4 * k4[i] + D5 * k5[i] + D6 * k6[i] + D7 * f1[i]);
        }
        Ok(())
    }

    fn dense(&self, s: f64, out: &mut [f64; M]) {
        let s1 = 1.0 - s;
        let [r1, r2, r3, r4, r5] = &self.cont;
        for i in 0..M {
            out[i] = r1[i] + s * (r2[i] + s1 * (r3[i] + s * (r4[i] + s1 * r5[i])));
        }
    }
}
