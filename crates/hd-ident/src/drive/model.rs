//! The rigid drive that `hdw fit drive` identifies: one inertia (or mass) driven by a force
//! (or torque) proportional to a command, against friction and a constant offset. With
//! Coulomb + viscous friction (which may differ by direction):
//!
//! `M·ẍ = g·u − F_f(ẋ) − offset`, `F_f(v) = Fv±·v + Fc±·sign(v)` (the `+` values for v > 0, the
//! `−` values for v < 0), sticking at v = 0 while |g·u − offset| does not exceed the Coulomb
//! level of the direction it pushes.
//!
//! With LuGre friction (a bristle state, Stribeck levels) the drive is [`LuGreDrive`].
//!
//! Units follow the axis ([`Axis`]): a linear axis (ball screw, belt) in kg, N, m; a rotary
//! one in kg·m², N·m, rad. The parameter names are the friction law's ([`FrictionLaw::names`])
//! plus the drive gain `gain` [N/V or N·m/V].

use super::dual::Scalar;
use super::lugre::LuGreDrive;

/// What kind of motion the axis makes; sets the units of every parameter and output.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Axis {
    /// Translation: mass [kg], force [N], position [m].
    #[default]
    Linear,
    /// Rotation: inertia [kg·m²], torque [N·m], angle [rad].
    Rotary,
}

impl Axis {
    /// Parse `linear` or `rotary`.
    pub fn parse(s: &str) -> Option<Axis> {
        [Axis::Linear, Axis::Rotary].into_iter().find(|a| a.name() == s)
    }

    /// The name used in configurations and reports (`linear`, `rotary`).
    pub fn name(self) -> &'static str {
        match self {
            Axis::Linear => "linear",
            Axis::Rotary => "rotary",
        }
    }

    /// Unit of force/torque.
    pub fn force_unit(self) -> &'static str {
        match self {
            Axis::Linear => "N",
            Axis::Rotary => "N·m",
        }
    }

    /// Unit of position.
    pub fn position_unit(self) -> &'static str {
        match self {
            Axis::Linear => "m",
            Axis::Rotary => "rad",
        }
    }

    /// Unit of a named parameter.
    pub fn unit_of(self, name: &str) -> &'static str {
        let lin = self == Axis::Linear;
        match name {
            "M" => {
                if lin {
                    "kg"
                } else {
                    "kg·m²"
                }
            }
            n if n.starts_with("Fv") || n == "sigma1" => {
                if lin {
                    "N·s/m"
                } else {
                    "N·m·s/rad"
                }
            }
            "sigma0" => {
                if lin {
                    "N/m"
                } else {
                    "N·m/rad"
                }
            }
            "vs" => {
                if lin {
                    "m/s"
                } else {
                    "rad/s"
                }
            }
            "gain" => {
                if lin {
                    "N/V"
                } else {
                    "N·m/V"
                }
            }
            _ => self.force_unit(),
        }
    }
}

/// The friction law of the drive.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrictionLaw {
    /// `Fv·v + Fc·sign(v)`, the same in both directions, plus an offset.
    CoulombViscous,
    /// Separate viscous and Coulomb levels for positive and negative speeds (they absorb
    /// the offset, which is not separable from them).
    Directional,
    /// LuGre: bristle stiffness σ0 and damping σ1, viscous Fv, Coulomb Fc and static Fs
    /// levels with Stribeck speed vs, the same both ways, plus an offset.
    LuGre,
    /// LuGre with viscous, Coulomb and static levels for each direction (one Stribeck
    /// speed, one bristle); the levels absorb the offset.
    DirectionalLuGre,
}

impl FrictionLaw {
    /// Every law, in the order `--friction all` fits them.
    pub const ALL: [FrictionLaw; 4] = [
        FrictionLaw::CoulombViscous,
        FrictionLaw::Directional,
        FrictionLaw::LuGre,
        FrictionLaw::DirectionalLuGre,
    ];

    /// The name used in configurations and reports.
    pub fn name(self) -> &'static str {
        match self {
            FrictionLaw::CoulombViscous => "coulomb-viscous",
            FrictionLaw::Directional => "directional",
            FrictionLaw::LuGre => "lugre",
            FrictionLaw::DirectionalLuGre => "directional-lugre",
        }
    }

    /// The Coulomb–viscous law with the same directions: the inverse-model start and the
    /// first fit of a LuGre law, whose values start the LuGre fit.
    pub fn base(self) -> FrictionLaw {
        match self {
            FrictionLaw::LuGre => FrictionLaw::CoulombViscous,
            FrictionLaw::DirectionalLuGre => FrictionLaw::Directional,
            l => l,
        }
    }

    /// Whether the law carries a bristle state.
    pub fn is_lugre(self) -> bool {
        self.base() != self
    }

    /// Parse a law's name.
    pub fn parse(s: &str) -> Option<FrictionLaw> {
        FrictionLaw::ALL.into_iter().find(|l| l.name() == s)
    }

    /// The parameters of a drive with this law, in the order of a parameter vector; the
    /// last is always `gain`.
    pub fn names(self) -> &'static [&'static str] {
        match self {
            FrictionLaw::CoulombViscous => &["M", "Fv", "Fc", "offset", "gain"],
            FrictionLaw::Directional => &["M", "Fv_pos", "Fc_pos", "Fv_neg", "Fc_neg", "gain"],
            FrictionLaw::LuGre => {
                &["M", "Fv", "Fc", "offset", "Fs", "vs", "sigma0", "sigma1", "gain"]
            }
            FrictionLaw::DirectionalLuGre => &[
                "M", "Fv_pos", "Fc_pos", "Fv_neg", "Fc_neg", "Fs_pos", "Fs_neg", "vs", "sigma0",
                "sigma1", "gain",
            ],
        }
    }

    /// The drive described by parameter vector `p` (in the order of [`FrictionLaw::names`]).
    pub fn drive<T: Scalar>(self, p: &[T]) -> Drive<T> {
        match self {
            FrictionLaw::CoulombViscous => Drive::Rigid(Rigid {
                m: p[0],
                fv_pos: p[1],
                fc_pos: p[2],
                fv_neg: p[1],
                fc_neg: p[2],
                offset: p[3],
                gain: p[4],
            }),
            FrictionLaw::Directional => Drive::Rigid(Rigid {
                m: p[0],
                fv_pos: p[1],
                fc_pos: p[2],
                fv_neg: p[3],
                fc_neg: p[4],
                offset: T::cst(0.0),
                gain: p[5],
            }),
            FrictionLaw::LuGre => Drive::LuGre(LuGreDrive {
                m: p[0],
                fv_pos: p[1],
                fv_neg: p[1],
                fc_pos: p[2],
                fc_neg: p[2],
                offset: p[3],
                fs_pos: p[4],
                fs_neg: p[4],
                vs: p[5],
                sigma0: p[6],
                sigma1: p[7],
                gain: p[8],
            }),
            FrictionLaw::DirectionalLuGre => Drive::LuGre(LuGreDrive {
                m: p[0],
                fv_pos: p[1],
                fc_pos: p[2],
                fv_neg: p[3],
                fc_neg: p[4],
                fs_pos: p[5],
                fs_neg: p[6],
                vs: p[7],
                sigma0: p[8],
                sigma1: p[9],
                offset: T::cst(0.0),
                gain: p[10],
            }),
        }
    }
}

/// A drive of either kind.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Drive<T> {
    /// Coulomb + viscous friction, stepped exactly.
    Rigid(Rigid<T>),
    /// LuGre friction.
    LuGre(LuGreDrive<T>),
}

impl<T: Scalar> Drive<T> {
    /// Force per unit command [N/V or N·m/V].
    pub fn gain(&self) -> T {
        match self {
            Drive::Rigid(d) => d.gain,
            Drive::LuGre(d) => d.gain,
        }
    }

    /// The motion after `h` [s] under the constant drive force `f` [N or N·m] from `s`.
    pub fn step(&self, s: Motion<T>, f: T, h: f64) -> Motion<T> {
        match self {
            Drive::Rigid(d) => d.step(s, f, h),
            Drive::LuGre(d) => d.step(s, f, h),
        }
    }
}

/// A rigid drive's parameters, in the axis's units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rigid<T> {
    /// Mass or inertia [kg or kg·m²].
    pub m: T,
    /// Viscous friction for v > 0 [N·s/m or N·m·s/rad].
    pub fv_pos: T,
    /// Coulomb friction for v > 0 [N or N·m].
    pub fc_pos: T,
    /// Viscous friction for v < 0 [N·s/m or N·m·s/rad].
    pub fv_neg: T,
    /// Coulomb friction for v < 0 (a positive level) [N or N·m].
    pub fc_neg: T,
    /// Constant force opposing the drive [N or N·m].
    pub offset: T,
    /// Force per unit command [N/V or N·m/V].
    pub gain: T,
}

/// Position and speed of the drive [m, m/s or rad, rad/s], and the LuGre bristle force and
/// mean friction force of the last substep [N or N·m] (both zero for Coulomb–viscous
/// friction).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion<T> {
    /// Position.
    pub x: T,
    /// Speed.
    pub v: T,
    /// Bristle force σ0·z.
    pub w: T,
    /// Mean friction force over the last substep (the next step's predictor starts from it).
    pub friction: T,
}

impl<T: Scalar> Motion<T> {
    /// At rest at `x`, bristle unloaded.
    pub fn rest(x: T) -> Self {
        Motion { x, v: T::cst(0.0), w: T::cst(0.0), friction: T::cst(0.0) }
    }
}

/// `(1 − e^{−a·t})/a` and `(a·t − 1 + e^{−a·t})/a²`: the speed and position responses of a
/// first-order lag to a unit speed and a unit acceleration, well-behaved as a → 0.
fn lag_integrals<T: Scalar>(a: T, t: T) -> (T, T) {
    let at = a * t;
    let one_minus = -(-at).exp_m1(); // 1 − e^{−at}
    let phi1 = one_minus / a;
    let phi2 = if at.re().abs() < 1e-3 {
        // Series: t²/2 · (1 − at/3 + (at)²/12 − (at)³/60).
        t * t * 0.5 * (T::cst(1.0) - at / 3.0 + at * at / 12.0 - at * at * at / 60.0)
    } else {
        (at - one_minus) / (a * a)
    };
    (phi1, phi2)
}

impl<T: Scalar> Rigid<T> {
    /// The motion after `h` [s] under a constant drive force `f` [N or N·m] (the command
    /// times the gain), from `s`: the exact solution of the piecewise-linear equation,
    /// sliding, stopping where the speed reaches zero, then sticking or sliding back.
    pub fn step(&self, s: Motion<T>, f: T, h: f64) -> Motion<T> {
        let net = f - self.offset; // the force the friction must balance at rest
        let mut s = s;
        let mut left = T::cst(h);
        // At most: slide → stop → slide the other way (which then never stops again).
        for _ in 0..3 {
            let dir = if s.v.re() > 0.0 {
                1.0
            } else if s.v.re() < 0.0 {
                -1.0
            } else if net.re() > self.fc_pos.re() {
                1.0
            } else if net.re() < -self.fc_neg.re() {
                -1.0
            } else {
                return Motion { v: T::cst(0.0), ..s }; // sticks for the rest of the step
            };
            let (fv, fc) =
                if dir > 0.0 { (self.fv_pos, self.fc_pos) } else { (self.fv_neg, self.fc_neg) };
            let a = fv / self.m; // [1/s]
            let acc0 = (net - fc * dir) / self.m; // acceleration at zero speed [m/s²]
            // Does the speed reach zero within the time left?
            if acc0.re() * dir < 0.0 {
                // v(t) = v·e^{−at} + acc0·(1 − e^{−at})/a = 0 at t = ln(1 + a·v/(−acc0))/a.
                let stop =
                    if a.re() == 0.0 { s.v / (-acc0) } else { (a * s.v / (-acc0)).ln_1p() / a };
                if stop.re() < left.re() {
                    let (p1, p2) = lag_integrals(a, stop);
                    s = Motion { x: s.x + s.v * p1 + acc0 * p2, v: T::cst(0.0), ..s };
                    left = left - stop;
                    continue;
                }
            }
            let (p1, p2) = lag_integrals(a, left);
            let e = (-(a * left)).exp();
            return Motion { x: s.x + s.v * p1 + acc0 * p2, v: s.v * e + acc0 * p1, ..s };
        }
        s
    }
}
