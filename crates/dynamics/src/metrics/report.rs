//! The metrics' report: each metric's name and value from an accumulator, and the names
//! formatted once per layout.

use std::f64::consts::{PI, TAU};

use super::{AXES, MetricsAccumulator, forces};

impl MetricsAccumulator {
    /// The metrics, names as documented in the module.
    pub fn finish(&self) -> Vec<(String, f64)> {
        self.finish_only(None)
    }

    /// [`Self::finish`] keeping only the metrics named in `wanted` (all: `None`), in
    /// `finish`'s order: the others' names are not copied (a copy was most of what a window
    /// of a §3.3 sensitivity spent finishing).
    pub fn finish_only(&self, wanted: Option<&[String]>) -> Vec<(String, f64)> {
        let names = self.names();
        let mut out: Vec<(String, f64)> =
            Vec::with_capacity(wanted.map_or(names.len(), <[String]>::len));
        let mut index = 0;
        self.each(&mut |_, value| {
            let name = &names[index];
            index += 1;
            if wanted.is_none_or(|wanted| wanted.contains(name)) {
                out.push((name.clone(), value));
            }
        });
        if let Some(needs) = self.lean {
            for (name, value) in &mut out {
                if !needs.provides(name) {
                    *value = f64::NAN;
                }
            }
        }
        out
    }

    /// The names [`Self::finish`] gives, formatted once per process for each layout (one or
    /// two wings, forces or not, a weight or not): formatting them was half of finishing a
    /// window (docs/findings.md §30).
    fn names(&self) -> &'static [String] {
        static LAYOUTS: [std::sync::OnceLock<Vec<String>>; 8] =
            [const { std::sync::OnceLock::new() }; 8];
        let layout = usize::from(self.n_wings == 2)
            | usize::from(self.forces.is_some()) << 1
            | usize::from(self.weight.is_some()) << 2;
        LAYOUTS[layout].get_or_init(|| {
            let mut names = Vec::with_capacity(64);
            self.each(&mut |name, _| names.push(name.text()));
            names
        })
    }

    /// Every metric's name and value, in [`Self::finish`]'s order (its one definition).
    fn each(&self, push: &mut impl FnMut(Name, f64)) {
        let n = self.body_samples.max(1) as f64;
        let duration = self.last_time - self.first_time.unwrap_or(self.last_time);
        let cycles = self.period.map_or(1.0, |p| (duration / p).round().max(1.0));
        let prefixes: &[&str] = if self.n_wings == 2 {
            &["left", "right"]
        } else {
            &["wing"]
        };
        for (w, p) in prefixes.iter().enumerate() {
            let a = &self.wings[w];
            push(Name::Wing(p, "stroke_amplitude"), 0.5 * a.phi.range.span());
            push(Name::Wing(p, "stroke_peak_to_peak"), a.phi.range.span());
            push(Name::Wing(p, "stroke_mean"), a.phi.mean(n));
            push(
                Name::Wing(p, "rotation_amplitude"),
                0.5 * a.psi.range.span(),
            );
            push(Name::Wing(p, "rotation_mean"), a.psi.mean(n));
            let lag = match self.period {
                Some(_) if a.psi.range.span() > 1e-9 && self.body_samples > 1 => {
                    wrap(a.phi_f.1.atan2(a.phi_f.0) - a.psi_f.1.atan2(a.psi_f.0))
                }
                _ => f64::NAN,
            };
            push(Name::Wing(p, "rotation_phase_lag"), lag);
            push(Name::Wing(p, "roll_aero_peak"), a.roll_aero.range.abs_max());
            push(Name::Wing(p, "roll_aero_mean"), a.roll_aero.mean(n));
        }
        push(
            Name::Plain("work_actuator_per_cycle"),
            self.work_actuator / cycles,
        );
        push(Name::Plain("work_aero_per_cycle"), self.work_aero / cycles);
        push(
            Name::Plain("mean_actuator_power"),
            if duration > 0.0 {
                self.work_actuator / duration
            } else {
                0.0
            },
        );
        push(Name::Plain("actuator_force_peak"), self.force.abs_max());
        push(Name::Plain("q2_amplitude"), 0.5 * self.q2.span());
        push(
            Name::Plain("roll_total_peak"),
            self.total[0].range.abs_max(),
        );
        // Added with the streamed engine (after the original names, which keep their order).
        for (w, p) in prefixes.iter().enumerate() {
            for (k, axis) in AXES.iter().enumerate() {
                let t = &self.wings[w].torque[k];
                push(Name::WingAxis(p, axis, "mean"), t.mean(n));
                push(Name::WingAxis(p, axis, "rms"), t.rms(n));
                push(Name::WingAxis(p, axis, "peak"), t.range.abs_max());
            }
        }
        for (k, axis) in AXES.iter().enumerate() {
            let t = &self.total[k];
            push(Name::Axis(axis, "total_mean"), t.mean(n));
            push(Name::Axis(axis, "total_rms"), t.rms(n));
            if k > 0 {
                push(Name::Axis(axis, "total_peak"), t.range.abs_max());
            }
        }
        if self.n_wings == 2 {
            let delta = self.delta_tau.abs_max();
            let tau_l = self.wings[0].roll_aero.range.abs_max();
            let tau_r = self.wings[1].roll_aero.range.abs_max();
            push(Name::Plain("delta_tau_peak"), delta);
            push(Name::Plain("tau_l_peak"), tau_l);
            push(Name::Plain("tau_r_peak"), tau_r);
            let percent = |x: f64| {
                if tau_r > 0.0 {
                    100.0 * x / tau_r
                } else {
                    f64::NAN
                }
            };
            push(Name::Plain("imbalance_instantaneous_pct"), percent(delta));
            push(Name::Plain("imbalance_peak_pct"), percent(tau_r - tau_l));
        }
        let per_time = |work: f64| {
            if duration > 0.0 { work / duration } else { 0.0 }
        };
        let actuator_power = per_time(self.work_actuator);
        let mut lift = f64::NAN;
        if let Some(acc) = &self.forces {
            for (w, p) in prefixes.iter().enumerate() {
                for (k, axis) in forces::FORCE_AXES.iter().enumerate() {
                    let f = &acc.wings[w][k];
                    push(Name::WingAxis(p, axis, "mean"), f.mean(n));
                    push(Name::WingAxis(p, axis, "rms"), f.rms(n));
                    push(Name::WingAxis(p, axis, "peak"), f.range.abs_max());
                }
            }
            for (k, axis) in forces::FORCE_AXES.iter().enumerate() {
                let f = &acc.net[k];
                push(Name::Axis(axis, "mean"), f.mean(n));
                push(Name::Axis(axis, "rms"), f.rms(n));
                push(Name::Axis(axis, "peak"), f.range.abs_max());
            }
            push(Name::Plain("aero_force_peak"), acc.magnitude.hi.max(0.0));
            lift = acc.net[0].mean(n);
        }
        // −work_aero: the power the wings give to the air is positive.
        push(Name::Plain("aero_power_mean"), -per_time(self.work_aero));
        push(Name::Plain("actuator_power_mean"), actuator_power);
        let ratio = |x: f64, by: f64| if by != 0.0 { x / by } else { f64::NAN };
        if self.forces.is_some() {
            push(Name::Plain("lift_per_power"), ratio(lift, actuator_power));
            if let Some(weight) = self.weight {
                push(Name::Plain("lift_to_weight"), ratio(lift, weight));
            }
        }
        if let Some(weight) = self.weight {
            // mW/mN = W/N: the input power per newton carried.
            push(
                Name::Plain("actuator_power_per_weight"),
                ratio(actuator_power, weight),
            );
        }
    }
}

/// A metric's name in parts, formatted only when [`MetricsAccumulator::names`] lists a layout.
#[derive(Clone, Copy)]
enum Name {
    /// The name itself.
    Plain(&'static str),
    /// `{prefix}_{field}`: a wing's.
    Wing(&'static str, &'static str),
    /// `{prefix}_{axis}_{statistic}`: a wing's, about a body axis.
    WingAxis(&'static str, &'static str, &'static str),
    /// `{axis}_{field}`: the net one about a body axis.
    Axis(&'static str, &'static str),
}

impl Name {
    fn text(self) -> String {
        match self {
            Name::Plain(name) => name.to_string(),
            Name::Wing(p, field) => format!("{p}_{field}"),
            Name::WingAxis(p, axis, statistic) => format!("{p}_{axis}_{statistic}"),
            Name::Axis(axis, field) => format!("{axis}_{field}"),
        }
    }
}

fn wrap(a: f64) -> f64 {
    let mut a = (a + PI).rem_euclid(TAU) - PI;
    if a <= -PI {
        a += TAU;
    }
    a
}

#[cfg(test)]
mod tests {
    use super::*;

    fn accumulator(n_wings: usize, forces: bool, weight: bool) -> MetricsAccumulator {
        MetricsAccumulator::of_layout(n_wings, Some(10.0), forces)
            .with_weight(weight.then_some(1.0))
    }

    /// The names kept per layout are each layout's own, whatever layout came first: every
    /// layout, twice over in two orders, against its names formatted anew.
    #[test]
    fn kept_names_are_each_layouts_own() {
        let layouts: Vec<(usize, bool, bool)> = (0..8)
            .map(|i| (1 + (i & 1), i & 2 != 0, i & 4 != 0))
            .collect();
        for (n_wings, forces, weight) in layouts.iter().chain(layouts.iter().rev()) {
            let acc = accumulator(*n_wings, *forces, *weight);
            let mut fresh = Vec::new();
            acc.each(&mut |name, _| fresh.push(name.text()));
            let kept: Vec<String> = acc.finish().into_iter().map(|(name, _)| name).collect();
            assert_eq!(
                kept, fresh,
                "{n_wings} wings, forces {forces}, weight {weight}"
            );
            let has = |name: &str| kept.iter().any(|k| k == name);
            assert_eq!(has("delta_tau_peak"), *n_wings == 2);
            assert_eq!(has("left_yaw_rms"), *n_wings == 2);
            assert_eq!(has("wing_stroke_amplitude"), *n_wings == 1);
            assert_eq!(has("lift_mean"), *forces);
            assert_eq!(has("lift_to_weight"), *forces && *weight);
            assert_eq!(has("actuator_power_per_weight"), *weight);
        }
    }
}
