//! The validated model: what a model file means once every key has been checked
//! and every node label resolved. Built by [`crate::model::load_model`]; consumed
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
}

/// Cross-section and material, per unit length.
#[derive(Debug, Clone, PartialEq)]
pub struct SectionSpec {
    pub name: String,
    /// Axial stiffness EA.
    pub ea: f64,
    /// Shear stiffnesses GA2, GA3.
    pub ga: [f64; 2],
    /// Torsional stiffness GJ.
    pub gj: f64,
    /// Bending stiffnesses EI2, EI3.
    pub ei: [f64; 2],
    /// Mass per unit length ρA (0 allowed in statics).
    pub rho_a: f64,
    /// Rotational inertia per unit length `ρ(I2+I3), ρI2, ρI3`.
    pub rho_j: [f64; 3],
}

/// Initial geometry of a beam.
#[derive(Debug, Clone, PartialEq)]
pub enum BeamGeometry {
    /// Straight from `start` to `end`; `e2` is the section's second axis (not
    /// parallel to the beam; it is orthogonalised against the beam axis).
    Straight {
        start: [f64; 3],
        end: [f64; 3],
        e2: [f64; 3],
    },
    /// Circular arc: starts at `start`, turns about `normal` (unit) through
    /// `sweep` radians around `center`. Tangent at start is
    /// `normal × (start − center)/radius`. `e2` defaults to the direction from
    /// the point towards the center.
    Arc {
        start: [f64; 3],
        center: [f64; 3],
        normal: [f64; 3],
        sweep: f64,
        e2: Option<[f64; 3]>,
    },
}

/// A beam meshed into equal elements.
#[derive(Debug, Clone, PartialEq)]
pub struct BeamSpec {
    pub name: String,
    /// Index into [`Model::sections`].
    pub section: usize,
    pub geometry: BeamGeometry,
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
    pub node: NodeRef,
    /// `[ux, uy, uz, rx, ry, rz]`: true where fixed.
    pub fixed: [bool; 6],
}

#[derive(Debug, Clone, PartialEq)]
pub struct JointSpec {
    pub name: String,
    /// The registered kind and its parameters ([`super::JointRegistry`]).
    pub kind: super::JointKind,
    pub master: NodeRef,
    pub slave: NodeRef,
    /// Initial released angle ψ₀ (default 0).
    pub angle: f64,
    /// Initial released angular rate (default 0).
    pub rate: f64,
}

#[derive(Debug, Clone, PartialEq)]
pub struct LoadSpec {
    pub node: NodeRef,
    pub force: [f64; 3],
    pub moment: [f64; 3],
    /// `None` when the file gives no `time` table.
    pub time: Option<TimeFunction>,
}

#[derive(Debug, Clone, PartialEq)]
pub enum PrescribedSpec {
    /// The released angle of joint `joint` (index into [`Model::joints`]) follows `angle`.
    JointAngle { joint: usize, angle: TimeFunction },
    /// DOF `dof` (0..6 = ux,uy,uz,rx,ry,rz) of `node` follows `value`
    /// (displacement from the initial position / rotation-vector component).
    NodeDof {
        node: NodeRef,
        dof: usize,
        value: TimeFunction,
    },
}

#[derive(Debug, Clone, PartialEq)]
pub struct InitialVelocitySpec {
    pub nodes: Vec<NodeRef>,
    pub linear: [f64; 3],
    pub angular: [f64; 3],
    pub origin: [f64; 3],
}

/// The time integrators: the solvers' own enum, one vocabulary for model
/// files and Rust (`IntegratorKind::name` gives the model-file name).
pub use flexmech_integrators::dynamics::Integrator as IntegratorKind;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MassKind {
    Consistent,
    Lumped,
}

#[derive(Debug, Clone, PartialEq)]
pub enum Analysis {
    /// Load factor from 0 to 1 in `load_steps` equal steps.
    Static { load_steps: usize },
    Dynamic {
        integrator: IntegratorKind,
        dt: f64,
        t_end: f64,
    },
}

#[derive(Debug, Clone, PartialEq)]
pub struct SolverSpec {
    pub analysis: Analysis,
    pub tolerance: f64,
    pub max_iterations: usize,
    pub max_halvings: usize,
    pub mass: MassKind,
    /// `newton = "modified"`: keep a factorised tangent while it converges
    /// fast enough (dynamic analyses; default `"full"`).
    pub modified_newton: bool,
}

#[derive(Debug, Clone, PartialEq)]
pub struct OutputSpec {
    pub every: usize,
    /// Tracked nodes: the label as written in the file and the node it names.
    pub track: Vec<(String, NodeRef)>,
}

/// A validated model file.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    pub name: String,
    /// The file the model came from (for error messages).
    pub path: PathBuf,
    /// The TOML text, stored verbatim in result files.
    pub source_text: String,
    pub gravity: [f64; 3],
    pub sections: Vec<SectionSpec>,
    pub beams: Vec<BeamSpec>,
    pub supports: Vec<SupportSpec>,
    pub joints: Vec<JointSpec>,
    pub loads: Vec<LoadSpec>,
    pub prescribed: Vec<PrescribedSpec>,
    pub initial_velocities: Vec<InitialVelocitySpec>,
    pub solver: SolverSpec,
    pub output: OutputSpec,
}
