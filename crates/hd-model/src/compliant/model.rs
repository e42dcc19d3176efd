//! The compliant drive that `hdw fit drive` identifies from a voltage test: the simulator's
//! `full` variant (docs/model.md §2): a DC motor (algebraic current), a gear with a cubic
//! spring and a hysteretic term (the fading memory, a Bouc–Wen element, or Maxwell-slip
//! elements), LuGre friction on the wave generator's speed (or on the load's), and an
//! inertial load with a constant load torque TL.
//!
//! ```text
//! i = (u − Ke·ωj)/R
//! Jj·ω̇j = Km·i − Cj·ωj − (Tb + Tf)/N        Jz·ω̇z = Tb − Cz·ωz − TL
//! θ̇ = ωj/N − ωz                Tb = c·θ + b·θ² + a·θ³ + z + α·h,  ż = A·θ̇ − B·z
//! ḣ = θ̇·(A_bw − |h|ⁿ·(β·sgn(θ̇·h) + γ))       (Bouc–Wen deflection h [rad])
//! or Tb = c·θ + b·θ² + a·θ³ + Σ (ms_k/n)·clamp(θ + oᵢ, ±δᵢ),  δᵢ = ms_delta·i/n (slip)
//! v = ωj/N,  ṡ = v − |v|·w/G(v),  ẇ = σ0·ṡ,  Tf = w + σ1·ṡ + σ2·v
//! ```
//!
//! With the friction on the load (`friction_velocity = "load"`: an output bearing's or a
//! guide's friction), v = ωz and Tf moves from the motor's equation to the load's:
//! `Jj·ω̇j = Km·i − Cj·ωj − Tb/N`, `Jz·ω̇z = Tb − Tf − Cz·ωz − TL`. Across the gear
//! (`"deflection"`: the teeth's own friction), v = θ̇ and Tf acts on both sides:
//! `Jj·ω̇j = Km·i − Cj·ωj − (Tb + Tf)/N`, `Jz·ω̇z = Tb + Tf − Cz·ωz − TL`.
//!
//! Friction on both sides: hd-model's load-side law (the `*_load` parameters, present when
//! one of its levels is non-zero, [`has_load_law`]) is a second LuGre law (symmetric, or
//! with its negative side's own levels) on v_L = ωz with its own bristle w_L, beside the
//! gear's on the motor's side:
//! `Jz·ω̇z = Tb − Tf_L − Cz·ωz − TL`, `Tf_L = w_L + σ1_L·ṡ_L + σ2_L·ωz`.
//!
//! Which hysteretic term a drive has is which of its parameters is non-zero ([`gear_law`]):
//! the fit holds the others' at zero, and a run skips a term whose constant is zero. The
//! slip elements (`ms_n` of them, evenly spread as hd-model's `maxwell-slip` law spreads
//! them) are carried as hd-model carries them: each by its offset oᵢ = eᵢ − θ, held over a
//! step (the element torque is then a continuous function of θ) and moved along the
//! step's deflection by the play operator when the step is taken ([`Compliant::commit`]).
//!
//! Every law is hd-model's (the cubic spring, the fading memory, Bouc–Wen, the LuGre level G): each is
//! evaluated in `f64` by its own code and enters the generic arithmetic through
//! [`Scalar::lift`] with its partial derivatives, so the same code gives plain runs and
//! runs carrying the exact sensitivities to the parameters.

use crate::FrictionVelocity;
use crate::balance::Chain;
use crate::dual::Scalar;
use crate::laws::bouc_wen::BoucWen;
use crate::laws::catalogue::{CatalogueCurve, DEFAULT_SMOOTHING};
use crate::laws::friction::LuGre;
use crate::laws::slip_set::MAX_SLIP;
use crate::laws::stiffness::{CubicSpring, FadingMemory};

pub use super::params::{
    LAWS, LOAD_LAW, NAMES, P, gear_law, has_load_law, hysteresis_of, in_drive, in_law, ix, on_law,
};

/// The state: motor angle θj [rad] and speed ωj [rad/s], gear deflection θ [rad] (θz =
/// θj/N − θ), load speed ωz [rad/s], memory torque z [N·m], bristle torque w = σ0·s
/// [N·m], the Bouc–Wen element's deflection h [rad] and the load-side law's bristle
/// torque w_L [N·m].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct State<T> {
    /// Motor angle θj [rad].
    pub theta_j: T,
    /// Motor speed ωj [rad/s].
    pub omega_j: T,
    /// Gear deflection θ [rad].
    pub theta: T,
    /// Load speed ωz [rad/s].
    pub omega_z: T,
    /// Memory torque z [N·m].
    pub z: T,
    /// Bristle torque w [N·m].
    pub w: T,
    /// Bouc–Wen deflection h [rad] (its torque is α·h).
    pub h: T,
    /// Bristle torque of the load-side law w_L [N·m] (zero without that law).
    pub w_load: T,
}

impl<T: Scalar> State<T> {
    /// At rest at motor angle `theta_j` [rad], gear unloaded.
    pub fn rest(theta_j: f64) -> Self {
        let o = T::cst(0.0);
        State {
            theta_j: T::cst(theta_j),
            omega_j: o,
            theta: o,
            omega_z: o,
            z: o,
            w: o,
            h: o,
            w_load: o,
        }
    }

    /// `self + k·h`.
    #[inline(always)]
    pub(crate) fn add(&self, k: &State<T>, h: f64) -> State<T> {
        State {
            theta_j: self.theta_j + k.theta_j * h,
            omega_j: self.omega_j + k.omega_j * h,
            theta: self.theta + k.theta * h,
            omega_z: self.omega_z + k.omega_z * h,
            z: self.z + k.z * h,
            w: self.w + k.w * h,
            h: self.h + k.h * h,
            w_load: self.w_load + k.w_load * h,
        }
    }
}

/// The compliant drive at one parameter vector (order of [`NAMES`]) and gear ratio N.
#[derive(Clone, Debug)]
pub struct Compliant<T> {
    /// Every parameter, [`NAMES`] order.
    pub p: [T; P],
    /// Gear ratio N [–] (known from the gear's data, never fitted).
    pub n: f64,
    /// Where the gear's friction law acts (hd-model's `friction_velocity`): on the wave
    /// generator (v = ωj/N, Tf/N on the motor), on the load alone (v = ωz, −Tf on the load)
    /// or across the gear (v = θ̇ = ωj/N − ωz, Tf/N on the motor and +Tf on the load).
    pub friction_velocity: FrictionVelocity,
    /// The LuGre law at the current values (f64: its level and slope are lifted).
    law: LuGre,
    /// The load-side law at the current values, when the drive has one ([`has_load_law`]).
    pub(crate) law_load: Option<LuGre>,
    /// The catalogue curve at the current values, when the gear has it ([`gear_law`]).
    catalogue: Option<CatalogueCurve>,
    /// The torque balance at the values of Jj, Jz, Cj and Cz (read when the drive is
    /// made: changing those in `p` afterwards does not reach it).
    chain: Chain<T>,
}

impl<T: Scalar> Compliant<T> {
    /// The drive with parameters `p` ([`NAMES`] order) and ratio `n`.
    pub fn new(p: [T; P], n: f64) -> Self {
        use ix::*;
        let law = lugre_at(&p, GEAR_LUGRE);
        let law_load = has_load_law(&p.map(|x| x.re())).then(|| lugre_at(&p, LOAD_LUGRE));
        // A curve hd-model would refuse (a rate ≤ 0, T2 ≤ T1) runs as NaN: a fit's trial
        // there fails and is not taken, so a fit never ends on a curve `hdw simulate` refuses.
        let catalogue = (p[CAT_K1].re() != 0.0).then(|| {
            let [k1, k2, k3, t1, t2] = [CAT_K1, CAT_K2, CAT_K3, CAT_T1, CAT_T2].map(|k| p[k].re());
            CatalogueCurve::new(k1, k2, k3, t1, t2).unwrap_or(CatalogueCurve {
                k1: f64::NAN,
                k2,
                k3,
                t1,
                t2,
                smoothing: DEFAULT_SMOOTHING,
            })
        });
        let fv = FrictionVelocity::Motor;
        let chain = Chain::new(n, p[JJ], p[JZ], p[CJ], p[CZ], fv);
        Compliant { p, n, friction_velocity: fv, law, law_load, catalogue, chain }
    }

    /// The same drive with its gear's friction law acting where `fv` says.
    pub fn with_friction_velocity(self, fv: FrictionVelocity) -> Self {
        let chain = Chain { friction_velocity: fv, ..self.chain };
        Compliant { friction_velocity: fv, chain, ..self }
    }

    /// The drive's torque balance ([`crate::balance`]).
    pub fn chain(&self) -> &Chain<T> {
        &self.chain
    }

    /// The friction law's sliding speed v [rad/s] in state `y`: ωj/N on the wave
    /// generator, ωz on the load, θ̇ = ωj/N − ωz across the gear ([`Chain::speeds`]).
    #[inline(always)]
    pub fn sliding_speed(&self, y: &State<T>) -> T {
        self.chain.speeds(y.omega_j, y.omega_z).1
    }

    /// Armature current at voltage `u` [V] and motor speed ωj [A].
    pub fn current(&self, u: f64, omega_j: T) -> T {
        (T::cst(u) - self.p[ix::KE] * omega_j) / self.p[ix::R]
    }

    /// The Stribeck level G(v) [N·m] of the gear's law with its derivatives.
    #[inline(always)]
    fn level(&self, v: T) -> T {
        self.lugre_level(&self.law, v, GEAR_LUGRE)
    }

    /// The load-side law's Stribeck level G_L(v) [N·m] with its derivatives.
    #[inline]
    fn level_load(&self, law: &LuGre, v: T) -> T {
        self.lugre_level(law, v, LOAD_LUGRE)
    }

    /// The Stribeck level of LuGre law `law` at speed `v`, lifted with its derivatives
    /// (hd-model's law): along v, and along its levels and Stribeck speed, the parameters
    /// of that law in `at` ([`GEAR_LUGRE`] order). The negative side's levels are
    /// their own parameters; a symmetric fit ties them to Tc and Ts, so their derivatives
    /// land there.
    #[inline(always)]
    fn lugre_level(&self, law: &LuGre, v: T, at: [usize; 8]) -> T {
        let lg = law.level_grad(v.re());
        let g = lg.grad;
        let p = &self.p;
        T::lift(
            lg.level,
            &[
                (lg.slope, v),
                (g[0], p[at[3]]),
                (g[1], p[at[4]]),
                (g[2], p[at[5]]),
                (g[4], p[at[6]]),
                (g[5], p[at[7]]),
            ],
        )
    }

    /// The load-side law's bristle rate ẇ_L and torque Tf_L [N·m] at load speed ωz and
    /// bristle torque w_L (zero without the law).
    #[inline]
    fn load_friction(&self, omega_z: T, w_load: T) -> (T, T) {
        use ix::*;
        let Some(law) = &self.law_load else { return (T::cst(0.0), T::cst(0.0)) };
        let p = &self.p;
        let g = self.level_load(law, omega_z);
        let s_rate = omega_z - omega_z.abs() * w_load / g;
        (p[SIGMA0_L] * s_rate, w_load + p[SIGMA1_L] * s_rate + p[SIGMA2_L] * omega_z)
    }

    /// The load-side bristle's relaxation rate λ_L = σ0_L·|ωz|/G_L(ωz) [1/s] and the value
    /// it relaxes to, sign(ωz)·G_L(ωz) [N·m] (both 0 without the law).
    pub fn relaxation_load(&self, y: &State<T>) -> (T, T) {
        match &self.law_load {
            Some(law) => {
                let g = self.level_load(law, y.omega_z);
                (self.p[ix::SIGMA0_L] * y.omega_z.abs() / g, signed(y.omega_z, g))
            }
            None => (T::cst(0.0), T::cst(0.0)),
        }
    }

    /// The catalogue curve's torque at deflection θ [N·m] (hd-model's rounded
    /// three-segment curve, lifted with its exact derivatives).
    #[inline(never)]
    fn catalogue_torque(&self, curve: &CatalogueCurve, theta: T) -> T {
        use ix::*;
        let (t, slope, g) = curve.torque_grad(theta.re());
        let p = &self.p;
        T::lift(
            t,
            &[
                (slope, theta),
                (g[0], p[CAT_K1]),
                (g[1], p[CAT_K2]),
                (g[2], p[CAT_K3]),
                (g[3], p[CAT_T1]),
                (g[4], p[CAT_T2]),
            ],
        )
    }

    /// The spring torque c·θ + b·θ² + a·θ³ [N·m] (hd-model's cubic spring, lifted).
    #[inline]
    fn spring(&self, theta: T) -> T {
        use ix::*;
        let t = theta.re();
        let law = CubicSpring { a: self.p[A].re(), b: self.p[B].re(), c: self.p[C].re() };
        T::lift(
            law.torque(t),
            &[(law.slope(t), theta), (t, self.p[C]), (t * t, self.p[B]), (t * t * t, self.p[A])],
        )
    }

    /// The memory rate ż = A·θ̇ − B·z [N·m/s] (hd-model's fading memory, lifted).
    #[inline]
    fn memory_rate(&self, theta_dot: T, z: T) -> T {
        use ix::*;
        let law = FadingMemory { a: self.p[MEM_A].re(), b: self.p[MEM_B].re() };
        let (td, zr) = (theta_dot.re(), z.re());
        T::lift(
            law.rate(td, zr),
            &[(law.a, theta_dot), (-law.b, z), (td, self.p[MEM_A]), (-zr, self.p[MEM_B])],
        )
    }

    /// The Bouc–Wen element's deflection rate ḣ [rad/s] at deflection rate θ̇ and state h
    /// (hd-model's law, lifted; zero when its stiffness α is zero).
    #[inline(never)]
    fn bouc_wen_rate(&self, theta_dot: T, h: T) -> T {
        use ix::*;
        let law = BoucWen {
            alpha: self.p[BW_ALPHA].re(),
            a: self.p[BW_A].re(),
            beta: self.p[BW_BETA].re(),
            gamma: self.p[BW_GAMMA].re(),
            n: self.p[BW_N].re(),
        };
        let (td, hr) = (theta_dot.re(), h.re());
        let s = (td * hr).signum();
        let ah = hr.abs();
        let pn = ah.powf(law.n);
        let shape = law.beta * s + law.gamma;
        // ∂|h|ⁿ/∂h = n·|h|ⁿ/h (0 at h = 0); ∂|h|ⁿ/∂n = |h|ⁿ·ln|h| (0 at h = 0).
        let dpn_dh = if ah > 0.0 { law.n * pn / hr } else { 0.0 };
        let dpn_dn = if ah > 0.0 { pn * ah.ln() } else { 0.0 };
        T::lift(
            law.rate(td, hr),
            &[
                (law.slope(hr, td.signum()), theta_dot),
                (-td * dpn_dh * shape, h),
                (td, self.p[BW_A]),
                (-td * pn * s, self.p[BW_BETA]),
                (-td * pn, self.p[BW_GAMMA]),
                (-td * dpn_dn * shape, self.p[BW_N]),
            ],
        )
    }

    /// The bristle's relaxation rate λ = σ0·|v|/G(v) [1/s] at state `y` and the value it
    /// relaxes to, sign(v)·G(v) [N·m] (0 at rest): the stiff part of the bristle equation,
    /// ẇ = λ·(sign(v)·G − w).
    pub fn relaxation(&self, y: &State<T>) -> (T, T) {
        let v = self.sliding_speed(y);
        let g = self.level(v);
        (self.p[ix::SIGMA0] * v.abs() / g, signed(v, g))
    }

    /// Number of slip elements: `ms_n` when the gear is Maxwell-slip (ms_k ≠ 0), else 0.
    pub fn slip_count(&self) -> usize {
        if self.p[ix::MS_K].re() == 0.0 {
            return 0;
        }
        (self.p[ix::MS_N].re().round().max(0.0) as usize).min(MAX_SLIP)
    }

    /// The yield deflection δᵢ = ms_delta·(i + 1)/n of slip element i of `count` [rad].
    fn yield_of(&self, i: usize, count: usize) -> T {
        self.p[ix::MS_DELTA] * ((i + 1) as f64 / count as f64)
    }

    /// The slip elements' torque Σ (ms_k/n)·clamp(θ + oᵢ, −δᵢ, δᵢ) [N·m] at deflection θ
    /// with offsets `o` (hd-model's `SlipSet::torque` for its even set).
    #[inline(never)]
    fn slip_torque(&self, theta: T, o: &[T]) -> T {
        let count = o.len();
        let mut sum = T::cst(0.0);
        for (i, &oi) in o.iter().enumerate() {
            sum = sum + clamp(theta + oi, self.yield_of(i, count));
        }
        sum * self.p[ix::MS_K] / count.max(1) as f64
    }

    /// Move the slip elements' offsets `o` along a step from `from` to `to`: each element's
    /// deflection follows the play operator over the step's deflection change (taken as
    /// monotone over a substep) and its offset becomes its new deflection less θ.
    #[inline(never)]
    pub fn commit(&self, from: &State<T>, to: &State<T>, o: &mut [T]) {
        let count = o.len();
        for (i, oi) in o.iter_mut().enumerate() {
            let d = self.yield_of(i, count);
            let e0 = clamp(from.theta + *oi, d);
            let e1 = clamp(e0 + (to.theta - from.theta), d);
            *oi = e1 - to.theta;
        }
    }

    /// The torque the gear transmits [N·m] in state `y`, the slip elements (if any) at
    /// offsets `o`: its spring, memory, Bouc–Wen, slip and catalogue parts (not the
    /// friction), as it acts on the load and, divided by N, against the motor.
    #[inline(always)]
    pub fn gear_torque(&self, y: &State<T>, o: &[T]) -> T {
        let mut tb = self.spring(y.theta) + y.z;
        if self.p[ix::BW_ALPHA].re() != 0.0 {
            tb = tb + self.p[ix::BW_ALPHA] * y.h;
        }
        if !o.is_empty() {
            tb = tb + self.slip_torque(y.theta, o);
        }
        if let Some(curve) = &self.catalogue {
            tb = tb + self.catalogue_torque(curve, y.theta);
        }
        tb
    }

    /// The state's rates at voltage `u` [V], the slip elements (if any) at offsets `o`.
    #[inline]
    pub fn rates(&self, y: &State<T>, u: f64, o: &[T]) -> State<T> {
        use ix::*;
        let p = &self.p;
        let (theta_dot, v) = self.chain.speeds(y.omega_j, y.omega_z);
        let bouc_wen = p[BW_ALPHA].re() != 0.0;
        let tb = self.gear_torque(y, o);
        let g = self.level(v);
        let s_rate = v - v.abs() * y.w / g;
        let tf = y.w + p[SIGMA1] * s_rate + p[SIGMA2] * v;
        let i = self.current(u, y.omega_j);
        let (w_load_rate, tf_load) = self.load_friction(y.omega_z, y.w_load);
        let g = self.chain.gear_torques(tb, tf, tf_load);
        let (omega_j, omega_z) =
            self.chain.accelerations(y.omega_j, y.omega_z, p[KM] * i, &g, p[TL]);
        State {
            theta_j: y.omega_j,
            omega_j,
            theta: theta_dot,
            omega_z,
            z: self.memory_rate(theta_dot, y.z),
            w: p[SIGMA0] * s_rate,
            h: if bouc_wen { self.bouc_wen_rate(theta_dot, y.h) } else { T::cst(0.0) },
            w_load: w_load_rate,
        }
    }

    /// The fastest rate of the drive's non-stiff dynamics [1/s]: the gear's resonance seen
    /// from the load and from the motor (spring plus memory: c + A at high frequency), the
    /// bristle–motor oscillation, the memory's decay and the damping rates. The bristle's
    /// relaxation is not among them: the integrating factor carries it.
    pub fn fastest_rate(&self) -> f64 {
        use ix::*;
        let r = |k: usize| self.p[k].re().abs();
        let n2 = self.n * self.n;
        let k_gear = r(C)
            + r(MEM_A)
            + r(BW_ALPHA) * r(BW_A)
            + r(MS_K)
            + r(CAT_K1).max(r(CAT_K2)).max(r(CAT_K3));
        let j_motor = r(JJ) * n2; // the motor inertia seen from the load
        let j_red = r(JZ) * j_motor / (r(JZ) + j_motor);
        // The inertia the bristle and its damping move, seen from the load.
        let j_fric = match self.friction_velocity {
            FrictionVelocity::Motor => j_motor,
            FrictionVelocity::Load => r(JZ),
            FrictionVelocity::Deflection => j_red,
        };
        let load_law = self.law_load.is_some();
        let if_load = |x: f64| if load_law { x } else { 0.0 };
        [
            if_load((r(SIGMA0_L) / r(JZ)).sqrt()),
            if_load((r(SIGMA1_L) + r(SIGMA2_L)) / r(JZ)),
            (k_gear / j_red).sqrt(),
            (r(SIGMA0) / j_fric).sqrt(),
            r(MEM_B),
            r(CJ) / r(JJ),
            r(CZ) / r(JZ),
            (r(SIGMA1) + r(SIGMA2)) / j_fric,
            r(KE) * r(KM) / (r(R) * r(JJ)),
        ]
        .into_iter()
        .filter(|x| x.is_finite())
        .fold(0.0, f64::max)
    }
}

/// The gear's LuGre law's parameters: σ0, σ1, σ2, Tc, Ts, ωs, Tc_neg, Ts_neg.
const GEAR_LUGRE: [usize; 8] =
    [ix::SIGMA0, ix::SIGMA1, ix::SIGMA2, ix::TC, ix::TS, ix::WS, ix::TC_NEG, ix::TS_NEG];

/// The load-side LuGre law's parameters, in [`GEAR_LUGRE`] order.
const LOAD_LUGRE: [usize; 8] = [
    ix::SIGMA0_L,
    ix::SIGMA1_L,
    ix::SIGMA2_L,
    ix::TC_L,
    ix::TS_L,
    ix::WS_L,
    ix::TC_NEG_L,
    ix::TS_NEG_L,
];

/// hd-model's LuGre law at the values of parameters `at` ([`GEAR_LUGRE`] order) of `p`.
fn lugre_at<T: Scalar>(p: &[T; P], at: [usize; 8]) -> LuGre {
    let v = at.map(|k| p[k].re());
    LuGre { tc_neg: v[6], ts_neg: v[7], ..LuGre::symmetric(v[0], v[1], v[2], v[3], v[4], v[5]) }
}

/// `g` with the sign of `v` (0 at v = 0).
fn signed<T: Scalar>(v: T, g: T) -> T {
    match v.re() {
        x if x > 0.0 => g,
        x if x < 0.0 => -g,
        _ => T::cst(0.0),
    }
}

/// x clamped to [−d, d] (d ≥ 0), carrying the derivative of whichever it is.
fn clamp<T: Scalar>(x: T, d: T) -> T {
    let (xr, dr) = (x.re(), d.re());
    if xr.abs() < dr {
        x
    } else if xr > 0.0 {
        d
    } else {
        -d
    }
}
