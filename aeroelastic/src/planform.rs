//! The planform of a lifting surface: chord and leading-edge offset per body, linear along each
//! body (taper), and how the lattice's sections are cut (normal to the beam axis or along the
//! stream).

/// A length given for every body of a surface at once, or per body as `[root, tip]`, linear
/// along the body (`aero.chord`, `aero.le_offset`).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(untagged))]
pub enum Taper {
    /// One value on every body, m.
    Uniform(f64),
    /// `[root, tip]` per body in the surface's body order, m, linear along each body.
    PerBody(Vec<[f64; 2]>),
}

impl From<f64> for Taper {
    fn from(v: f64) -> Self {
        Self::Uniform(v)
    }
}

impl Taper {
    /// The value on body `body` at the fraction `frac` of its length (0 at the root, 1 at the
    /// tip). A uniform value, or equal root and tip, is returned exactly (`r + frac · 0`).
    pub fn at(&self, body: usize, frac: f64) -> f64 {
        match self {
            Self::Uniform(v) => *v,
            Self::PerBody(v) => v.get(body).map_or(f64::NAN, |&[r, t]| r + frac * (t - r)),
        }
    }

    /// Every root and tip value (the extremes of a linear distribution).
    pub fn values(&self) -> Vec<f64> {
        match self {
            Self::Uniform(v) => vec![*v],
            Self::PerBody(v) => v.iter().flatten().copied().collect(),
        }
    }

    /// The largest value, m.
    pub fn max(&self) -> f64 {
        self.values().into_iter().fold(f64::NEG_INFINITY, f64::max)
    }

    /// The smallest value, m.
    pub fn min(&self) -> f64 {
        self.values().into_iter().fold(f64::INFINITY, f64::min)
    }

    /// Check against `n_bodies` bodies: one entry per body, every value finite and, with
    /// `positive`, above zero. The error names `field` and the entry.
    pub fn check(&self, field: &str, n_bodies: usize, positive: bool) -> Result<(), String> {
        let ok = |v: f64| v.is_finite() && (!positive || v > 0.0);
        let need = if positive { "a finite length > 0" } else { "finite" };
        match self {
            Self::Uniform(v) if !ok(*v) => Err(format!("{field}: {v} is not {need}")),
            Self::Uniform(_) => Ok(()),
            Self::PerBody(v) if v.len() != n_bodies => {
                Err(format!("{field}: {} [root, tip] entries for {n_bodies} bodies", v.len()))
            }
            Self::PerBody(v) => v.iter().enumerate().try_for_each(|(b, rt)| {
                for (k, x) in rt.iter().enumerate() {
                    if !ok(*x) {
                        return Err(format!("{field}[{b}][{k}]: {x} is not {need}"));
                    }
                }
                Ok(())
            }),
        }
    }
}

/// How the lattice's chordwise grid columns are cut.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Sections {
    /// Columns along each section's y axis, normal to the beam axis; `chord` and `le_offset` are
    /// measured along it (the default).
    #[default]
    Normal,
    /// Columns parallel to the free stream (without sideslip) in the reference configuration:
    /// the stream projected on each section's plane. `chord` and `le_offset` are measured along
    /// the stream. A swept wing then has streamwise root and tip edges, and its root lies in a
    /// plane of symmetry along the stream. Columns keep their slant as the structure deforms.
    Streamwise,
}

impl Sections {
    /// Whether these are the default normal sections.
    pub fn is_normal(&self) -> bool {
        *self == Self::Normal
    }
}

/// One lifting surface of `aero.surfaces`: a chain of bodies with its own planform, panels and
/// wake. Every surface sheds its own wake; all surfaces are solved in one influence system.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct LiftingSurface {
    /// Name (unique among the surfaces).
    pub name: String,
    /// Its bodies from root to tip, by name: each after the first the child of the one before
    /// through a flared hinge at that body's end.
    pub bodies: Vec<String>,
    /// Chord, m: one number, or `[root, tip]` per body of this surface, in its body order.
    pub chord: Taper,
    /// Distance from the beam axis to the leading edge along the section y axis, m, as `chord`.
    pub le_offset: Taper,
    /// Spanwise panels per body of this surface, in its body order.
    pub panels_per_body: Vec<usize>,
    /// How its grid columns are cut (as `aero.sections`); default normal.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Sections::is_normal"))]
    pub sections: Sections,
    /// Chordwise panels; default `aero.n_chordwise`.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
    pub n_chordwise: Option<usize>,
}

/// A lifting surface resolved against the problem's bodies: body indices from root to tip, the
/// planform per body of the surface (index `i` of `chord`/`le_offset` is `bodies[i]`), and the
/// field that names it in messages (`aero` for the one-surface shorthand, `aero.surfaces[k]`).
#[derive(Debug, Clone, PartialEq)]
pub struct SurfacePlan {
    /// Name (`wing` for the shorthand).
    pub name: String,
    /// The case-file field of its planform, for messages.
    pub field: String,
    /// Body indices from root to tip.
    pub bodies: Vec<usize>,
    /// Chord per body of the surface.
    pub chord: Taper,
    /// Leading-edge offset per body of the surface.
    pub le_offset: Taper,
    /// Spanwise panels per body of the surface.
    pub panels: Vec<usize>,
    /// How its grid columns are cut.
    pub sections: Sections,
    /// Chordwise panels.
    pub n_chordwise: usize,
}

impl SurfacePlan {
    /// Check the planform's lists against the surface's bodies and its panels (at least 1 each).
    pub fn check(&self) -> Result<(), String> {
        let n = self.bodies.len();
        self.chord.check(&format!("{}.chord", self.field), n, true)?;
        self.le_offset.check(&format!("{}.le_offset", self.field), n, false)?;
        if self.panels.len() != n {
            return Err(format!("{}.panels_per_body: {} entries for {n} bodies", self.field, self.panels.len()));
        }
        if let Some(i) = self.panels.iter().position(|&p| p == 0) {
            return Err(format!("{}.panels_per_body[{i}]: must be at least 1", self.field));
        }
        if self.n_chordwise == 0 {
            return Err(format!("{}.n_chordwise: must be at least 1", self.field));
        }
        Ok(())
    }

    /// Position of body `b` in this surface, if it is one of its bodies.
    pub fn position(&self, b: usize) -> Option<usize> {
        self.bodies.iter().position(|&x| x == b)
    }
}
