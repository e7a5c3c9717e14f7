//! Drivetrain configurations: one file per configuration, one registry line each.
//!
//! A configuration is a serde struct (its fields are the spec fields under `[drivetrain]`)
//! implementing [`DrivetrainConfig`]: how it builds the planar kinematics and which balance
//! spring it puts on `q2`. `registry!` turns the list below into the tagged enum
//! [`Drivetrain`] (`kind = "<snake_case name>"`), its JSON Schema and the dispatch.

use paritysim_error::Result;
use paritysim_kinematics::Drivetrain as Kinematics;

mod dual_four_bar;
mod dual_linear;
mod hmf_four_bar;
mod linear_differential;
mod linkage_differential;
mod polynomial;
mod single_linear;

pub use dual_four_bar::DualFourBar;
pub use dual_linear::DualLinear;
pub use hmf_four_bar::HmfFourBar;
pub use linear_differential::LinearDifferential;
pub use linkage_differential::LinkageDifferential;
pub use single_linear::SingleLinear;

/// What a drivetrain configuration provides to the model.
pub trait DrivetrainConfig {
    /// The planar kinematics `φ(q)`.
    ///
    /// # Errors
    /// [`paritysim_error::Error::InvalidParameter`] naming the field (relative to
    /// `drivetrain`) for lengths the linkage cannot be built with.
    fn kinematics(&self) -> Result<Kinematics>;

    /// Balance-beam spring K2 on `q2` (mN·mm/rad); 0 for 1-DOF drivetrains.
    fn balance_spring(&self) -> f64 {
        0.0
    }

    /// A constant torque on the whippletree `q2` (mN·mm), e.g. a preloaded centring spring:
    /// the drive load on `q2` is `P − K2 q2` (`device/drive.rs`); 0 unless a configuration
    /// has one.
    fn balance_preload(&self) -> f64 {
        0.0
    }

    /// Viscous damping of the whippletree `q2` (mN·mm·ms/rad); 0 unless a configuration has
    /// one.
    fn balance_damping(&self) -> f64 {
        0.0
    }

    /// Cubic stiffness of the balance spring on `q2` (mN·mm/rad³); 0 unless a configuration
    /// has one.
    fn balance_cubic(&self) -> f64 {
        0.0
    }
}

macro_rules! registry {
    ($($(#[$doc:meta])* $variant:ident),+ $(,)?) => {
        /// A drivetrain spec, tagged by `kind`.
        #[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize, schemars::JsonSchema)]
        #[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
        pub enum Drivetrain {
            $($(#[$doc])* $variant($variant),)+
        }

        impl Drivetrain {
            fn config(&self) -> &dyn DrivetrainConfig {
                match self {
                    $(Drivetrain::$variant(c) => c,)+
                }
            }

            /// One default spec of every registered kind (for defaults and documentation).
            pub fn every_kind() -> Vec<Drivetrain> {
                vec![$(Drivetrain::$variant($variant::default()),)+]
            }
        }
    };
}

// The registry: add a line (and a file) for a new configuration.
registry! {
    /// HMF four-bar (§2.3.1), 1 DOF.
    HmfFourBar,
    /// Linearised differential of eq. 2.15, 2 DOF.
    LinearDifferential,
    /// The Drag PARITY linkage differential of §3.3.2, 2 DOF.
    LinkageDifferential,
    /// Two four-bars, one drive per wing (beyond the thesis), 2 DOF.
    DualFourBar,
    /// One actuator on a linear or polynomial transmission (beyond the thesis: a one-wing
    /// device, or two tied wings), 1 DOF.
    SingleLinear,
    /// A linear or polynomial drive per wing (beyond the thesis: RoboBee-class), 2 DOF.
    DualLinear,
}

impl Drivetrain {
    /// The planar kinematics.
    ///
    /// # Errors
    /// See [`DrivetrainConfig::kinematics`].
    pub fn kinematics(&self) -> Result<Kinematics> {
        self.config().kinematics()
    }

    /// K2 (mN·mm/rad).
    pub fn balance_spring(&self) -> f64 {
        self.config().balance_spring()
    }

    /// The preload torque on `q2` (mN·mm).
    pub fn balance_preload(&self) -> f64 {
        self.config().balance_preload()
    }

    /// Damping of the whippletree `q2` (mN·mm·ms/rad).
    pub fn balance_damping(&self) -> f64 {
        self.config().balance_damping()
    }

    /// Cubic stiffness of the balance spring (mN·mm/rad³).
    pub fn balance_cubic(&self) -> f64 {
        self.config().balance_cubic()
    }
}

impl Default for Drivetrain {
    fn default() -> Self {
        Drivetrain::LinkageDifferential(LinkageDifferential::default())
    }
}
