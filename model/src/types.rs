//! The validated model: what a model file means once every key has been checked
//! and every node label resolved. Built by [`crate::load_model`]; consumed
//! by the mechanism builder. Plain data, no behaviour beyond small helpers.

use std::path::PathBuf;

/// A node of the mesh: node `node` (0-based, along the beam) of beam `beam`
/// (index into [`Model::beams`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct NodeRef {
    /// Index of the beam in [`Model::beams`].
    pub beam: usize,
    /// Node index within the beam, `0..=elements*(nodes_per_element-1)`.
    pub node: usize,
}

/// A scale factor as a function of time (statics: of the load factor).
#[derive(Debug, Clone, PartialEq)]
pub enum TimeFunction {
    /// The same value at every time.
    Constant(f64),
    /// Piecewise-linear interpolation of `(t, value)` pairs sorted by `t`;
    /// constant extrapolation outside the table.
    Table(Vec<(f64, f64)>),
    /// An expression of `t` (statics: of the load factor), `{ expr = "…" }`,
    /// with exact derivatives.
    Expression(crate::expr::Expression),
}

/// The section values of the builder, one vocabulary for model files and
/// Rust: `EA`, `GA₂,₃`, `GJ`, `EI₂,₃`, `ρA`, `ρJ` per unit length.
pub use flexmech_integrators::builder::SectionValues;

/// A named `[[section]]`: cross-section and material, per unit length.
#[derive(Debug, Clone, PartialEq)]
pub struct SectionSpec {
    /// Its name (`section` of a beam refers to it).
    pub name: String,
    /// Its values (`rho_a` 0 allowed in statics).
    pub values: SectionValues,
    /// Kelvin–Voigt damping time `η` (`damping`, seconds; 0: undamped).
    pub damping: f64,
}

/// Initial geometry of a beam: the builder's [`BeamShape`](flexmech_integrators::builder::BeamShape),
/// one vocabulary for model files and Rust. `Straight { start, end, e2 }`:
/// `e2` is the section's second axis (not parallel to the beam; it is
/// orthogonalised against the beam axis). `Arc { start, center, normal,
/// sweep, e2 }`: starts at `start`, turns about the unit `normal` through
/// `sweep` radians around `center`; the tangent at start is
/// `normal × (start − center)/radius`; `e2` defaults to the direction from
/// the point towards the center.
pub use flexmech_integrators::builder::BeamShape as BeamGeometry;

/// A beam meshed into equal elements.
#[derive(Debug, Clone, PartialEq)]
pub struct BeamSpec {
    /// Its name (node labels start with it).
    pub name: String,
    /// Index into [`Model::sections`].
    pub section: usize,
    /// Its initial geometry.
    pub geometry: BeamGeometry,
    /// Number of elements.
    pub elements: usize,
    /// 2 (linear) or 3 (quadratic).
    pub nodes_per_element: usize,
}

impl BeamSpec {
    /// Number of nodes of the beam: `elements·(nodes_per_element − 1) + 1`.
    pub fn node_count(&self) -> usize {
        self.elements * (self.nodes_per_element - 1) + 1
    }
}

/// A support: the listed DOFs of a node are held at their initial values.
#[derive(Debug, Clone, PartialEq)]
pub struct SupportSpec {
    /// The supported node.
    pub node: NodeRef,
    /// `[ux, uy, uz, rx, ry, rz]`: true where fixed.
    pub fixed: [bool; 6],
}

/// A `[[joint]]`: a master–slave relation between two nodes.
#[derive(Debug, Clone, PartialEq)]
pub struct JointSpec {
    /// Its name (`/joints/<name>` in results).
    pub name: String,
    /// The registered kind and its parameters ([`super::JointRegistry`]).
    pub kind: super::JointKind,
    /// The master node (carries the joint frame); `None` for
    /// `master = "ground"`: the joint frame is fixed in space, at the
    /// slave's initial pose.
    pub master: Option<NodeRef>,
    /// The slave node (its DOFs are eliminated).
    pub slave: NodeRef,
    /// Initial released angle ψ₀ (default 0).
    pub angle: f64,
    /// Initial released angular rate (default 0).
    pub rate: f64,
}

/// A `[[load]]`: a dead force and a fixed-axis moment on a node, or with
/// `follower` a force and moment that turn with the node's triad.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadSpec {
    /// The loaded node.
    pub node: NodeRef,
    /// Force, global components (a follower load's at t = 0).
    pub force: [f64; 3],
    /// Moment about fixed global axes (a follower load's at t = 0).
    pub moment: [f64; 3],
    /// `None` when the file gives no `time` table.
    pub time: Option<TimeFunction>,
    /// `follower = true`: the load turns with the node.
    pub follower: bool,
}

/// A `[[distributed_load]]`: a dead force and a fixed-axis moment per unit
/// length on a whole beam, applied as consistent nodal loads (`∫ q Nᵢ ds`
/// over each element).
#[derive(Debug, Clone, PartialEq)]
pub struct DistributedLoadSpec {
    /// Index of the loaded beam in [`Model::beams`].
    pub beam: usize,
    /// Force per unit length, global components.
    pub force: [f64; 3],
    /// Moment per unit length about fixed global axes.
    pub moment: [f64; 3],
    /// `None` when the file gives no `time` table (as for `[[load]]`).
    pub time: Option<TimeFunction>,
    /// `follower = true`: the load turns with the beam's triads.
    pub follower: bool,
}

/// A `[[prescribed]]` motion.
#[derive(Debug, Clone, PartialEq)]
pub enum PrescribedSpec {
    /// The released angle of joint `joint` (index into [`Model::joints`]) follows `angle`.
    JointAngle {
        /// Index into [`Model::joints`].
        joint: usize,
        /// The angle over time.
        angle: TimeFunction,
    },
    /// DOF `dof` (0..6 = ux,uy,uz,rx,ry,rz) of `node` follows `value`
    /// (displacement from the initial position / rotation-vector component).
    NodeDof {
        /// The node.
        node: NodeRef,
        /// 0..6 = ux, uy, uz, rx, ry, rz.
        dof: usize,
        /// Its value over time.
        value: TimeFunction,
    },
}

/// An `[[initial_velocity]]`: a rigid-body velocity field on a set of nodes,
/// `v = linear + angular × (x − origin)`.
#[derive(Debug, Clone, PartialEq)]
pub struct InitialVelocitySpec {
    /// The nodes it applies to.
    pub nodes: Vec<NodeRef>,
    /// Velocity at `origin`.
    pub linear: [f64; 3],
    /// Angular velocity.
    pub angular: [f64; 3],
    /// Reference point of `linear`.
    pub origin: [f64; 3],
}

/// A `[[rigid_body]]`: a rigid body (a point mass when its inertia and
/// offset are zero) carried by a node.
#[derive(Debug, Clone, PartialEq)]
pub struct RigidBodySpec {
    /// Its name (its index `i` when the file gives none); the centre of
    /// mass of an offset body is the node `body.<name>` in results.
    pub name: String,
    /// The carrying node.
    pub node: NodeRef,
    /// Mass.
    pub mass: f64,
    /// Inertia tensor about the centre of mass in the node's initial frame
    /// (the global axes: every node starts at the identity).
    pub inertia: [[f64; 3]; 3],
    /// Centre of mass from the node, in the same frame.
    pub offset: [f64; 3],
}

/// The time integrators: the solvers' own enum, one vocabulary for model
/// files and Rust (`IntegratorKind::name` gives the model-file name).
pub use flexmech_integrators::dynamics::Integrator as IntegratorKind;

/// The eigensolvers of modal and buckling analyses: the solvers' own enum.
pub use flexmech_integrators::modal::EigenSolver;

/// How translational mass is distributed: the solvers' own enum.
pub use flexmech_core::MassKind;

/// What is solved.
#[derive(Debug, Clone, PartialEq)]
pub enum Analysis {
    /// Load factor from 0 to 1 in `load_steps` equal steps.
    Static {
        /// Number of equal load steps.
        load_steps: usize,
    },
    /// The static path by Crisfield's arc-length method
    /// (`[solver] control = "arc-length"`): past limit points, the load
    /// factor an unknown, until it reaches 1.
    ArcLength {
        /// The first step's load increment is `1/load_steps`; its arc
        /// length is the path's step.
        load_steps: usize,
        /// Most steps before the path must reach λ = 1.
        max_steps: usize,
        /// `branch_switch = true`: at the first bifurcation, leave the
        /// fundamental path along the critical mode.
        branch_switch: bool,
    },
    /// Vibration modes (`analysis = "modal"`): the `modes` lowest, about
    /// the initial state or — when the model is loaded or driven — about
    /// the static equilibrium at load factor 1 reached in `load_steps`.
    Modal {
        /// How many of the lowest modes.
        modes: usize,
        /// Load steps of the static path to the state (when loaded).
        load_steps: usize,
    },
    /// Linear buckling (`analysis = "buckling"`): the `modes` lowest
    /// positive load factors multiplying the model's loads.
    Buckling {
        /// How many load factors.
        modes: usize,
    },
    /// Time integration from 0 to `t_end`.
    Dynamic {
        /// The scheme.
        integrator: IntegratorKind,
        /// Nominal time step.
        dt: f64,
        /// End time.
        t_end: f64,
    },
}

impl Analysis {
    /// Whether loads and drivers follow the load factor (statics, arc-length,
    /// the preload of modes, buckling) rather than time.
    pub fn is_load_path(&self) -> bool {
        !matches!(self, Analysis::Dynamic { .. })
    }

    /// Whether the analysis needs the mass (dynamics, modes).
    pub fn needs_mass(&self) -> bool {
        matches!(self, Analysis::Dynamic { .. } | Analysis::Modal { .. })
    }

    /// The model-file name of the analysis (`solver.analysis`).
    pub fn name(&self) -> &'static str {
        match self {
            Analysis::Static { .. } | Analysis::ArcLength { .. } => "static",
            Analysis::Modal { .. } => "modal",
            Analysis::Buckling { .. } => "buckling",
            Analysis::Dynamic { .. } => "dynamic",
        }
    }
}

/// `[solver] rotation = { axis, origin, rate }`: the structure spins
/// steadily; statics and modes are in the frame turning with it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rotation {
    /// The spin axis (unit).
    pub axis: [f64; 3],
    /// A point of the axis.
    pub origin: [f64; 3],
    /// The spin rate Ω, radians per unit of model time.
    pub rate: f64,
}

/// `[solver] stop = { load_factor, displacement = { node, max } }`: where
/// an arc-length path ends before its budget.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PathStopSpec {
    /// The path ends where the load factor first reaches this (default 1,
    /// the model's loads).
    pub load_factor: Option<f64>,
    /// The path ends after the first step at which this node's
    /// displacement reaches `max`.
    pub displacement: Option<DisplacementStop>,
}

/// `stop.displacement = { node, max }`.
#[derive(Debug, Clone, PartialEq)]
pub struct DisplacementStop {
    /// The node's label as the file gives it.
    pub label: String,
    /// The node.
    pub node: NodeRef,
    /// The displacement `|x − X|` at which the path ends.
    pub max: f64,
}

/// `[solver]`.
#[derive(Debug, Clone, PartialEq)]
pub struct SolverSpec {
    /// Static or dynamic, with its steps.
    pub analysis: Analysis,
    /// Newton's tolerance on the scaled residual norm.
    pub tolerance: f64,
    /// Newton iterations per step before the step is halved.
    pub max_iterations: usize,
    /// Halvings of a step before the run stops.
    pub max_halvings: usize,
    /// Translational mass distribution.
    pub mass: MassKind,
    /// `newton = "modified"`: keep a factorised tangent while it converges
    /// fast enough (dynamic analyses; default `"full"`).
    pub modified_newton: bool,
    /// `newton = "exact"`: full Newton with the exact tangent at every
    /// iterate, also in the energy–momentum scheme, whose `"full"` Newton
    /// starts with a cheaper tangent (dynamic analyses).
    pub exact_tangent: bool,
    /// A steady spin of the frame (static and modal analyses).
    pub rotation: Option<Rotation>,
    /// `eigensolver = "dense" | "sparse"` of a modal or buckling analysis
    /// (`None`, `"auto"`: by the unknowns).
    pub eigensolver: Option<EigenSolver>,
    /// `stop = { … }` of an arc-length path (`None`: at load factor 1 or
    /// the budget).
    pub stop: Option<PathStopSpec>,
}

impl Default for SolverSpec {
    /// What a model file without `[solver]` means: statics in 10 load
    /// steps, Newton's default tolerance and iteration limit, 10 halvings,
    /// the consistent mass, full Newton.
    fn default() -> Self {
        Self {
            analysis: Analysis::Static { load_steps: 10 },
            tolerance: flexmech_integrators::newton::DEFAULT_TOLERANCE,
            max_iterations: flexmech_integrators::newton::DEFAULT_MAX_ITERATIONS,
            max_halvings: flexmech_integrators::dynamics::DEFAULT_MAX_HALVINGS,
            mass: MassKind::Consistent,
            modified_newton: false,
            exact_tangent: false,
            rotation: None,
            eigensolver: None,
            stop: None,
        }
    }
}

impl SolverSpec {
    /// The integrator and the settings a run of a dynamic analysis steps
    /// with (the command line's, the Python package's stepping); `None` for
    /// a static one.
    pub fn dynamic_settings(
        &self,
    ) -> Option<(
        IntegratorKind,
        flexmech_integrators::dynamics::DynamicSettings,
    )> {
        let Analysis::Dynamic {
            integrator,
            dt,
            t_end,
        } = self.analysis
        else {
            return None;
        };
        Some((integrator, self.stepping(dt, t_end)))
    }

    /// The settings of time steps of `dt` to `t_end` with this solver's
    /// Newton, halvings and mass.
    pub fn stepping(&self, dt: f64, t_end: f64) -> flexmech_integrators::dynamics::DynamicSettings {
        let newton = flexmech_integrators::NewtonSettings {
            tolerance: self.tolerance,
            max_iterations: self.max_iterations,
            modified: self.modified_newton,
            exact_tangent: self.exact_tangent,
        };
        flexmech_integrators::dynamics::DynamicSettings {
            dt,
            t_end,
            newton,
            max_halvings: self.max_halvings,
            mass: self.mass,
        }
    }
}

/// `[output]`; [`Default`]: every step, no tracked node, no resultants or
/// ParaView series.
#[derive(Debug, Clone, PartialEq)]
pub struct OutputSpec {
    /// Keep every k-th converged step (and the last).
    pub every: usize,
    /// Tracked nodes: the label as written in the file and the node it names.
    pub track: Vec<(String, NodeRef)>,
    /// `resultants = true`: write the stress resultants at every Gauss
    /// point (`/resultants`).
    pub resultants: bool,
    /// `vtk = true`: after the run, write its ParaView time series next to
    /// the result file (`<name>.pvd`, as `flexmech export --vtk` does).
    pub vtk: bool,
    /// `sensitivity = [...]`: the key paths as written and the model values
    /// they name; the run writes the exact derivatives of its results with
    /// respect to each (`/sensitivity/<key path>`).
    pub sensitivity: Vec<(String, SensitivityKey)>,
}

/// A model value a sensitivity is taken with respect to (`[output]
/// sensitivity`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SensitivityKey {
    /// Value `component` of section `section` (index into
    /// [`Model::sections`]): 0–5 are EA, GA₂, GA₃, GJ, EI₂, EI₃, 6 is ρA and
    /// 7–9 are ρJ (`rhoJ[0..2]`).
    Section {
        /// The section.
        section: usize,
        /// Which stiffness, 0–5.
        component: usize,
    },
    /// Component `component` (0–2 force, 3–5 moment) of `[[load]]` `load`.
    Load {
        /// Index into [`Model::loads`].
        load: usize,
        /// Which component, 0–5.
        component: usize,
    },
    /// Component `component` (0–2 force, 3–5 moment, per unit length) of
    /// `[[distributed_load]]` `load`.
    DistributedLoad {
        /// Index into [`Model::distributed_loads`].
        load: usize,
        /// Which component, 0–5.
        component: usize,
    },
    /// The mass (`component` 0) or a principal inertia (1–3, about the
    /// global axes at t = 0) of `[[rigid_body]]` `body`.
    BodyMass {
        /// Index into [`Model::rigid_bodies`].
        body: usize,
        /// Which value, 0–3.
        component: usize,
    },
    /// The parameter `name` of joint `joint` (index into [`Model::joints`];
    /// an expression joint's `parameters`).
    JointParameter {
        /// The joint.
        joint: usize,
        /// The parameter's name.
        name: String,
    },
    /// Coordinate `component` (0–2) of the start (`end` 0) or end (`end` 1)
    /// of straight `[[beam]]` `beam`: its nodes move along their places on
    /// the beam.
    BeamEnd {
        /// Index into [`Model::beams`].
        beam: usize,
        /// 0: `start`, 1: `end`.
        end: usize,
        /// Which coordinate, 0–2.
        component: usize,
    },
    /// Component `component` (0–2 `linear`, 3–5 `angular`) of
    /// `[[initial_velocity]]` `field` (dynamics).
    InitialVelocity {
        /// Index into [`Model::initial_velocities`].
        field: usize,
        /// Which component, 0–5.
        component: usize,
    },
}

impl Default for OutputSpec {
    fn default() -> Self {
        Self {
            every: 1,
            track: Vec::new(),
            resultants: false,
            vtk: false,
            sensitivity: Vec::new(),
        }
    }
}

/// The function of a [`RustLoad`]: at time `t` (statics: the load factor
/// λ) it adds, for the `k`-th of the load's nodes, the force and the
/// moment `[f₁, f₂, f₃, m₁, m₂, m₃]` (global axes, moment about fixed axes)
/// to `out[k]`. `out` holds zeros when it is called.
pub type NodeLoadFn = dyn Fn(f64, &mut [[f64; 6]]) + Send + Sync;

/// A shared [`NodeLoadFn`]. Two are equal when they are the same function
/// object (the same `Arc`); debug output shows `LoadFn(<fn>)`.
#[derive(Clone)]
pub struct LoadFn(pub std::sync::Arc<NodeLoadFn>);

impl LoadFn {
    /// Wraps a closure `f(t, out)` (see [`NodeLoadFn`]).
    pub fn new(f: impl Fn(f64, &mut [[f64; 6]]) + Send + Sync + 'static) -> Self {
        LoadFn(std::sync::Arc::new(f))
    }
}

impl std::fmt::Debug for LoadFn {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("LoadFn(<fn>)")
    }
}

impl PartialEq for LoadFn {
    fn eq(&self, other: &Self) -> bool {
        std::sync::Arc::ptr_eq(&self.0, &other.0)
    }
}

/// A `[[rust_load]]`: forces and moments on named nodes computed by a Rust
/// function of the program's (a wind field, a controller, a contact
/// law). The model file records the load's name and nodes; the function
/// itself lives only in the program, so a model with Rust load fields runs
/// and restarts only from a program that binds them
/// ([`Model::bind_load`], `ModelBuilder::rust_load`). Building a model
/// whose Rust load has no function is refused with a message saying so.
#[derive(Debug, Clone, PartialEq)]
pub struct RustLoad {
    /// The load's name, unique in the model (`[[rust_load]] name`).
    pub name: String,
    /// The loaded nodes, in the order of the function's `out` rows.
    pub nodes: Vec<NodeRef>,
    /// The function; `None` for a model read from text, until bound.
    pub field: Option<LoadFn>,
}

/// A validated model file. [`Default`] is the empty model (no name, no
/// beams, [`SolverSpec::default`]), for struct-update syntax in Rust:
/// `Model { name: "arm".into(), sections, beams, ..Model::default() }`;
/// [`crate::build()`] checks what it is given.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Model {
    /// The model's name (result file `<name>.h5`).
    pub name: String,
    /// The file the model came from (for error messages).
    pub path: PathBuf,
    /// The TOML text the model was read from (comments and all); empty for
    /// a model written as a Rust struct. Result files store it while the
    /// model still is what it says, else [`Model::to_toml`] (see
    /// [`Model::text`]).
    pub source_text: String,
    /// [`Model::to_toml`] of the model as `source_text` was read: a model
    /// changed in Rust since writes another text, and its result files
    /// store that one ([`Model::text`]).
    pub source_written: String,
    /// Gravity acceleration (acts on ρA).
    pub gravity: [f64; 3],
    /// `[[section]]` entries.
    pub sections: Vec<SectionSpec>,
    /// `[[beam]]` entries.
    pub beams: Vec<BeamSpec>,
    /// `[[support]]` entries.
    pub supports: Vec<SupportSpec>,
    /// `[[joint]]` entries.
    pub joints: Vec<JointSpec>,
    /// `[[load]]` entries.
    pub loads: Vec<LoadSpec>,
    /// `[[distributed_load]]` entries.
    pub distributed_loads: Vec<DistributedLoadSpec>,
    /// `[[prescribed]]` entries.
    pub prescribed: Vec<PrescribedSpec>,
    /// `[[initial_velocity]]` entries, in file order.
    pub initial_velocities: Vec<InitialVelocitySpec>,
    /// `[[rigid_body]]` entries (point masses included).
    pub rigid_bodies: Vec<RigidBodySpec>,
    /// `[[rust_load]]` entries: load fields whose function is Rust code of
    /// the program that runs the model (see [`RustLoad`]).
    pub rust_loads: Vec<RustLoad>,
    /// `[solver]`.
    pub solver: SolverSpec,
    /// `[output]`.
    pub output: OutputSpec,
}
