//! Splitting a sweep across processes: `--shard k/N` (or `--shard slurm`) on every command that
//! expands sweeps.
//!
//! A command lists its *units* of work — a case run (both formulations, and its static sweep),
//! a refinement ladder, a stress-matrix cell, an extra long run, a whole study — each with an
//! estimated cost ([`crate::budget::estimate`]'s seconds, or a multiple of it). [`assign`] deals
//! them to `N` shards by longest-processing-time first: units in decreasing cost (ties in list
//! order), each to the shard with the least cost so far (ties to the lowest index). The
//! assignment depends only on the unit list and `N`, so every shard of a job array computes the
//! same one and runs its own part; every unit belongs to exactly one shard, and no shard carries
//! more than 4/3 of the optimal largest load (Graham's bound).
//!
//! Each shard writes the files of its units as the unsharded command would, plus a manifest
//! `<out>/shards/<command>-<k>-of-<N>.json` (the whole unit list with each unit's shard, and the
//! units this shard finished) and, under `<out>/shards/<command>-<k>-of-<N>/`, the exact results
//! [`crate::merge`] needs to build the one report.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::Error;
use crate::case::{Formulation, RunSpec};

/// `--shard`: a fixed share `k/N` or the share of a SLURM array task.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShardArg {
    /// Shard `k` (1-based) of `n`.
    Fixed(Shard),
    /// From `SLURM_ARRAY_TASK_ID`, `SLURM_ARRAY_TASK_MIN` and `SLURM_ARRAY_TASK_COUNT`.
    Slurm,
}

/// One share of a sweep: shard `k` of `n`, 1 ≤ k ≤ n.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// This shard, 1-based.
    pub k: usize,
    /// Number of shards.
    pub n: usize,
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.k, self.n)
    }
}

impl Shard {
    /// Shard `k` of `n`; an error unless 1 ≤ k ≤ n.
    pub fn new(k: usize, n: usize) -> Result<Self, String> {
        if n == 0 || k == 0 || k > n {
            return Err(format!("--shard {k}/{n}: k must be in 1..=N and N at least 1"));
        }
        Ok(Self { k, n })
    }

    /// The file stem of this shard's manifest and results (`stress-2-of-8`).
    pub fn stem(&self, command: &str) -> String {
        format!("{command}-{}-of-{}", self.k, self.n)
    }
}

impl std::str::FromStr for ShardArg {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        if s == "slurm" {
            return Ok(Self::Slurm);
        }
        let bad = || format!("--shard `{s}`: expected k/N (1-based, e.g. 2/8) or `slurm`");
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let k: usize = k.trim().parse().map_err(|_| bad())?;
        let n: usize = n.trim().parse().map_err(|_| bad())?;
        Shard::new(k, n).map(Self::Fixed)
    }
}

impl ShardArg {
    /// The shard, reading the SLURM variables from the environment for [`ShardArg::Slurm`].
    pub fn resolve(self) -> Result<Shard, Error> {
        self.resolve_with(|v| std::env::var(v).ok())
    }

    /// As [`resolve`](Self::resolve), with the environment given (for tests). A task of an
    /// array `--array=A-B` is shard `SLURM_ARRAY_TASK_ID − SLURM_ARRAY_TASK_MIN + 1` of
    /// `SLURM_ARRAY_TASK_COUNT`; the array must be contiguous (no step, no list with gaps).
    pub fn resolve_with(self, env: impl Fn(&str) -> Option<String>) -> Result<Shard, Error> {
        match self {
            Self::Fixed(s) => Ok(s),
            Self::Slurm => {
                let get = |name: &str| -> Result<usize, Error> {
                    let v = env(name).ok_or_else(|| {
                        Error::Shard(format!("slurm: {name} is not set (not inside an sbatch --array task?)"))
                    })?;
                    v.trim().parse().map_err(|_| Error::Shard(format!("slurm: {name}={v} is not a number")))
                };
                let id = get("SLURM_ARRAY_TASK_ID")?;
                let count = get("SLURM_ARRAY_TASK_COUNT")?;
                let min = get("SLURM_ARRAY_TASK_MIN")?;
                let max = get("SLURM_ARRAY_TASK_MAX")?;
                if let Some(step) = env("SLURM_ARRAY_TASK_STEP").and_then(|s| s.trim().parse::<usize>().ok())
                    && step != 1
                {
                    return Err(Error::Shard(format!(
                        "slurm: the array has step {step}; give it as --array=A-B (contiguous)"
                    )));
                }
                if max + 1 != min + count {
                    return Err(Error::Shard(format!(
                        "slurm: the array {min}-{max} has {count} tasks, not contiguous; give it as --array=A-B"
                    )));
                }
                if id < min || id > max {
                    return Err(Error::Shard(format!("slurm: task {id} outside the array {min}-{max}")));
                }
                Shard::new(id - min + 1, count).map_err(|e| Error::Shard(format!("slurm: {e}")))
            }
        }
    }
}

/// One unit of work of a sharded command.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Unit {
    /// Unique name within the command (`run:<run>`, `stress:<f>:c=…`, `energy`).
    pub id: String,
    /// Estimated cost, s (only ratios matter).
    pub cost: f64,
}

/// The 0-based shard of every unit (longest processing time first; see the module docs).
///
/// # Panics
/// If `n` is zero.
pub fn assign(costs: &[f64], n: usize) -> Vec<usize> {
    assert!(n > 0, "at least one shard");
    let mut order: Vec<usize> = (0..costs.len()).collect();
    // A NaN cost counts as zero; total_cmp keeps the order total, the stable sort keeps ties in
    // list order.
    let cost = |i: usize| if costs[i].is_nan() { 0.0 } else { costs[i] };
    order.sort_by(|&a, &b| cost(b).total_cmp(&cost(a)));
    let mut load = vec![0.0_f64; n];
    let mut out = vec![0; costs.len()];
    for i in order {
        let s = (0..n).min_by(|&a, &b| load[a].total_cmp(&load[b]).then(a.cmp(&b))).expect("n > 0");
        load[s] += cost(i);
        out[i] = s;
    }
    out
}

/// The estimated cost of one run of both formulations, s.
pub fn run_cost(spec: &RunSpec) -> f64 {
    Formulation::ALL.iter().map(|&f| crate::budget::estimate(spec.case(f), f, None).seconds).sum()
}

/// A sharded command's plan: every unit, its shard, and this process's shard.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Plan {
    /// The command (`all`, `stress`, `converge`, `static`, …).
    pub command: String,
    /// This process's shard.
    pub shard: Shard,
    /// Every unit of the command, in the command's order.
    pub units: Vec<Unit>,
    /// The 1-based shard of each unit.
    pub owner: Vec<usize>,
}

impl Plan {
    /// Deal `units` to `shard.n` shards ([`assign`]). Unit names must be unique.
    pub fn new(command: &str, shard: Shard, units: Vec<Unit>) -> Result<Self, Error> {
        let mut seen = std::collections::HashSet::new();
        if let Some(u) = units.iter().find(|u| !seen.insert(u.id.as_str())) {
            return Err(Error::Shard(format!("two units of work are both named `{}`", u.id)));
        }
        let costs: Vec<f64> = units.iter().map(|u| u.cost).collect();
        let owner = assign(&costs, shard.n).into_iter().map(|s| s + 1).collect();
        Ok(Self { command: command.to_string(), shard, units, owner })
    }

    /// Whether the unit named `id` is this shard's (false for a name not in the plan).
    pub fn mine(&self, id: &str) -> bool {
        self.units.iter().zip(&self.owner).any(|(u, &o)| u.id == id && o == self.shard.k)
    }

    /// The names of this shard's units.
    pub fn my_units(&self) -> Vec<&str> {
        self.units.iter().zip(&self.owner).filter(|(_, o)| **o == self.shard.k).map(|(u, _)| u.id.as_str()).collect()
    }

    /// The estimated cost of each shard, s.
    pub fn loads(&self) -> Vec<f64> {
        let mut l = vec![0.0; self.shard.n];
        for (u, &o) in self.units.iter().zip(&self.owner) {
            l[o - 1] += u.cost;
        }
        l
    }

    /// This shard's folder of exact results for the merge (`<out>/shards/<command>-k-of-N/`).
    pub fn data_dir(&self, out: &Path) -> PathBuf {
        out.join(SHARDS_DIR).join(self.shard.stem(&self.command))
    }

    /// Write the manifest `<out>/shards/<command>-k-of-N.json`: the plan, the arguments the merge
    /// needs (`args`: the study folders' names, the matrix axes, …) and the units finished.
    pub fn write_manifest(&self, out: &Path, args: serde_json::Value, done: &[String]) -> Result<(), Error> {
        let m = Manifest { plan: self.clone(), args, done: done.to_vec() };
        let json = serde_json::to_string_pretty(&m).map_err(|e| Error::Io(e.to_string()))?;
        crate::atomic::write(
            &out.join(SHARDS_DIR).join(format!("{}.json", self.shard.stem(&self.command))),
            json.as_bytes(),
        )
    }

    /// One line for the log: this shard's units and estimated load against the others'.
    pub fn describe(&self) -> String {
        let loads = self.loads();
        let max = loads.iter().copied().fold(0.0, f64::max);
        format!(
            "shard {} of {}: {} of {} units, estimated load {:.3} of the largest shard's",
            self.shard.k,
            self.shard.n,
            self.my_units().len(),
            self.units.len(),
            if max > 0.0 { loads[self.shard.k - 1] / max } else { 1.0 }
        )
    }
}

/// The folder of the shards' manifests and exact results inside an output folder.
pub const SHARDS_DIR: &str = "shards";

/// What a shard leaves for [`crate::merge`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// The plan (every unit and its shard).
    pub plan: Plan,
    /// Command-specific arguments (study folder names, axes).
    pub args: serde_json::Value,
    /// The units this shard finished.
    pub done: Vec<String>,
}

/// The plan of a command when `--shard` is given (None without it), printing what this shard runs.
pub fn plan(command: &str, arg: Option<ShardArg>, units: impl FnOnce() -> Vec<Unit>) -> Result<Option<Plan>, Error> {
    let Some(arg) = arg else { return Ok(None) };
    let p = Plan::new(command, arg.resolve()?, units())?;
    println!("{command}: {}", p.describe());
    Ok(Some(p))
}

/// Whether unit `id` runs here: always without a plan, else when it is this shard's.
pub fn runs_here(plan: Option<&Plan>, id: &str) -> bool {
    plan.is_none_or(|p| p.mine(id))
}

/// The unit name of a case run.
pub fn run_unit(name: &str) -> String {
    format!("run:{name}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_fixed_and_slurm() {
        assert_eq!("2/8".parse::<ShardArg>(), Ok(ShardArg::Fixed(Shard { k: 2, n: 8 })));
        assert_eq!("slurm".parse::<ShardArg>(), Ok(ShardArg::Slurm));
        for bad in ["0/3", "4/3", "1/0", "x/2", "3", ""] {
            assert!(bad.parse::<ShardArg>().is_err(), "{bad}");
        }
    }

    #[test]
    fn slurm_task_ids_from_any_base() {
        let env = |id: &'static str, min: &'static str, max: &'static str, count: &'static str| {
            move |v: &str| -> Option<String> {
                match v {
                    "SLURM_ARRAY_TASK_ID" => Some(id.into()),
                    "SLURM_ARRAY_TASK_MIN" => Some(min.into()),
                    "SLURM_ARRAY_TASK_MAX" => Some(max.into()),
                    "SLURM_ARRAY_TASK_COUNT" => Some(count.into()),
                    _ => None,
                }
            }
        };
        assert_eq!(ShardArg::Slurm.resolve_with(env("0", "0", "3", "4")), Ok(Shard { k: 1, n: 4 }));
        assert_eq!(ShardArg::Slurm.resolve_with(env("4", "1", "4", "4")), Ok(Shard { k: 4, n: 4 }));
        assert!(ShardArg::Slurm.resolve_with(env("5", "1", "9", "3")).is_err());
        assert!(ShardArg::Slurm.resolve_with(|_| None).is_err());
    }

    #[test]
    fn longest_first_balances_and_is_deterministic() {
        let costs = [5.0, 1.0, 1.0, 4.0, 3.0, 2.0, 2.0, 2.0];
        let a = assign(&costs, 3);
        assert_eq!(a, assign(&costs, 3));
        let mut load = [0.0; 3];
        for (c, s) in costs.iter().zip(&a) {
            load[*s] += c;
        }
        assert_eq!(load, [7.0, 7.0, 6.0]);
    }
}
