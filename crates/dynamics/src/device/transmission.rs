//! A drivetrain with its balance-beam spring K2 and the whippletree's optional preload,
//! damping and cubic stiffness: what the one drive load (`drive.rs`) reads for `q2`.

use paritysim_error::{Result, check_non_negative};
use paritysim_kinematics::Drivetrain;

/// A drivetrain with its balance-beam spring (and an optional preload on the whippletree).
#[derive(Clone, Debug, PartialEq)]
pub struct Transmission {
    pub(super) kinematics: Drivetrain,
    pub(super) balance_spring: f64,
    pub(super) preload: f64,
    pub(super) balance_damping: f64,
    pub(super) balance_cubic: f64,
}

impl Transmission {
    /// `balance_spring` K2 on `q2` in mN·mm/rad (>= 0; docs/errata.md#14: not given by the
    /// thesis).
    pub fn new(kinematics: Drivetrain, balance_spring: f64) -> Result<Self> {
        Ok(Self {
            kinematics,
            balance_spring: check_non_negative("balance_spring", balance_spring)?,
            preload: 0.0,
            balance_damping: 0.0,
            balance_cubic: 0.0,
        })
    }

    /// With viscous damping `damping` (mN·mm·ms/rad: a torque `−b2 q̇2`) and a cubic stiffness
    /// `cubic` (mN·mm/rad³: a torque `−K2c q2³`) on the whippletree `q2` (the stroke flexure /
    /// balance spring). Both zero by default.
    ///
    /// # Errors
    /// [`paritysim_error::Error::InvalidParameter`] naming `balance_damping` or
    /// `balance_cubic` when negative, not finite, or nonzero on a drivetrain without a
    /// whippletree (1 DOF) or a dual one (`q2` is the right drive there: the actuator's terms
    /// act on it).
    pub fn with_balance_losses(mut self, damping: f64, cubic: f64) -> Result<Self> {
        let whippletree = self.kinematics.dof() == 2 && !self.kinematics.is_dual();
        for (name, value) in [("balance_damping", damping), ("balance_cubic", cubic)] {
            check_non_negative(name, value)?;
            if value != 0.0 && !whippletree {
                return Err(paritysim_error::Error::invalid(
                    name,
                    value,
                    "0 on a drivetrain without a whippletree (1 DOF, or dual: one drive per wing)",
                ));
            }
        }
        self.balance_damping = damping;
        self.balance_cubic = cubic;
        Ok(self)
    }

    /// Damping on the whippletree `q2` (mN·mm·ms/rad).
    pub fn balance_damping(&self) -> f64 {
        self.balance_damping
    }

    /// Cubic stiffness on the whippletree `q2` (mN·mm/rad³).
    pub fn balance_cubic(&self) -> f64 {
        self.balance_cubic
    }

    /// With a constant torque `preload` (mN·mm) on the whippletree `q2` (a preloaded centring
    /// spring: the drive load on `q2` becomes `P − K2 q2`).
    ///
    /// # Errors
    /// [`paritysim_error::Error::InvalidParameter`] naming `balance_preload` when it is not
    /// finite, or nonzero on a drivetrain without a whippletree (1 DOF) or without a balance
    /// spring (`P − 0·q2` has no equilibrium: the whippletree runs to its stop).
    pub fn with_preload(mut self, preload: f64) -> Result<Self> {
        if !preload.is_finite() || (preload != 0.0 && self.kinematics.dof() != 2) {
            return Err(paritysim_error::Error::invalid(
                "balance_preload",
                preload,
                "a finite torque (mN·mm), and 0 on a 1-DOF drivetrain",
            ));
        }
        if preload != 0.0 && self.balance_spring() == 0.0 {
            return Err(paritysim_error::Error::invalid(
                "balance_preload",
                preload,
                "0 without a balance spring (balance_spring > 0 gives the preload its \
                 equilibrium q2 = P / K2)",
            ));
        }
        self.preload = preload;
        Ok(self)
    }

    /// The preload torque on `q2` (mN·mm).
    pub fn preload(&self) -> f64 {
        self.preload
    }

    /// Drivetrain kinematics.
    pub fn kinematics(&self) -> &Drivetrain {
        &self.kinematics
    }

    /// K2 (mN·mm/rad).
    pub fn balance_spring(&self) -> f64 {
        self.balance_spring
    }
}
