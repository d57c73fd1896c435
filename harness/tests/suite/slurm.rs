//! The job-array template on a real SLURM: a one-node cluster on localhost (munged,
//! slurmctld and slurmd of Debian's `munge` and `slurm-wlm`, which `tools/ci-deps.sh` installs)
//! runs `cluster/flexmb-array.sbatch` as a 4-task array over a 16-run sweep; the merged report
//! must equal a single-machine run of the same sweep (CSV files byte for byte, summaries apart
//! from the measured times).
//!
//! Needs root (the daemons run as root with their state in a temporary folder) and the SLURM and
//! MUNGE binaries; without them it skips with a message, and under CI (`CI` set) it fails.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use super::external::{missing, root, temp_dir};
use super::shard::{assert_same_report, sweep16_cases};

/// A binary on the PATH or in /usr/sbin.
fn find(name: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&path)
        .chain([PathBuf::from("/usr/sbin"), PathBuf::from("/sbin")])
        .map(|d| d.join(name))
        .find(|p| p.is_file())
}

/// The daemons started by the test, ended (and reaped) when it ends however it ends.
struct Daemons(Vec<Child>);

impl Drop for Daemons {
    fn drop(&mut self) {
        for c in self.0.iter_mut().rev() {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

/// A TCP port free on localhost now.
fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

fn output(cmd: &mut Command) -> (bool, String) {
    match cmd.output() {
        Ok(o) => (
            o.status.success(),
            format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr)),
        ),
        Err(e) => (false, e.to_string()),
    }
}

/// The minimal `slurm.conf` of a one-node cluster on localhost with its state in `dir`.
fn slurm_conf(dir: &Path, host: &str, socket: &Path) -> String {
    let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mem_mb = std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|s| s.lines().find(|l| l.starts_with("MemTotal:"))?.split_whitespace().nth(1)?.parse::<u64>().ok())
        .map_or(1024, |kb| kb * 9 / 10 / 1024);
    let d = dir.display();
    format!(
        "ClusterName=flexmbci\n\
         SlurmctldHost={host}(127.0.0.1)\n\
         SlurmctldPort={ctld}\n\
         SlurmdPort={slurmd}\n\
         SlurmUser=root\n\
         SlurmdUser=root\n\
         AuthType=auth/munge\n\
         CredType=cred/munge\n\
         AuthInfo=socket={socket}\n\
         StateSaveLocation={d}/state\n\
         SlurmdSpoolDir={d}/spool\n\
         SlurmctldPidFile={d}/slurmctld.pid\n\
         SlurmdPidFile={d}/slurmd.pid\n\
         SlurmctldLogFile={d}/slurmctld.log\n\
         SlurmdLogFile={d}/slurmd.log\n\
         ProctrackType=proctrack/linuxproc\n\
         TaskPlugin=task/none\n\
         JobAcctGatherType=jobacct_gather/none\n\
         AccountingStorageType=accounting_storage/none\n\
         JobCompType=jobcomp/none\n\
         SchedulerType=sched/builtin\n\
         SelectType=select/cons_tres\n\
         SelectTypeParameters=CR_Core\n\
         MpiDefault=none\n\
         ReturnToService=2\n\
         InactiveLimit=0\n\
         KillWait=5\n\
         NodeName={host} NodeAddr=127.0.0.1 CPUs={cpus} RealMemory={mem_mb} State=UNKNOWN\n\
         PartitionName=ci Nodes={host} Default=YES MaxTime=INFINITE State=UP\n",
        ctld = free_port(),
        slurmd = free_port(),
        socket = socket.display(),
    )
}

#[test]
fn slurm_array_of_four_shards_merges_into_the_single_machine_report() {
    const TEST: &str = "slurm_array_of_four_shards_merges_into_the_single_machine_report";
    let t0 = Instant::now();
    #[cfg(target_os = "linux")]
    // SAFETY: geteuid has no preconditions.
    let is_root = unsafe { libc::geteuid() } == 0;
    #[cfg(not(target_os = "linux"))]
    let is_root = false;
    if !is_root {
        let _: Option<()> = missing(TEST, "not root on Linux (the test starts slurmctld and slurmd as root)");
        return;
    }
    let names = ["munged", "slurmctld", "slurmd", "sbatch", "sinfo"];
    let bins: Vec<PathBuf> = match names.iter().map(|n| find(n)).collect::<Option<Vec<_>>>() {
        Some(b) => b,
        None => {
            let _: Option<()> = missing(TEST, "no SLURM/MUNGE binaries (Debian's slurm-wlm and munge)");
            return;
        }
    };
    let [munged, slurmctld, slurmd, sbatch, sinfo] = <[PathBuf; 5]>::try_from(bins).unwrap();

    let dir = temp_dir("slurm");
    for d in ["munge", "state", "spool", "out"] {
        std::fs::create_dir_all(dir.join(d)).unwrap();
    }
    use std::os::unix::fs::PermissionsExt as _;
    std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o700)).unwrap();
    std::fs::set_permissions(dir.join("munge"), std::fs::Permissions::from_mode(0o700)).unwrap();
    // A MUNGE key of this test's own (1 KiB of the kernel's randomness), read by its own munged.
    let key = dir.join("munge/munge.key");
    let mut bytes = vec![0u8; 1024];
    {
        use std::io::Read as _;
        std::fs::File::open("/dev/urandom").unwrap().read_exact(&mut bytes).unwrap();
    }
    std::fs::write(&key, &bytes).unwrap();
    std::fs::set_permissions(&key, std::fs::Permissions::from_mode(0o400)).unwrap();
    let socket = dir.join("munge/munge.sock");
    let host = Command::new("hostname")
        .arg("-s")
        .output()
        .map_or_else(|_| "localhost".to_string(), |o| String::from_utf8_lossy(&o.stdout).trim().to_string());
    let conf = dir.join("slurm.conf");
    std::fs::write(&conf, slurm_conf(&dir, &host, &socket)).unwrap();

    let spawn = |cmd: &mut Command, what: &str| -> Child {
        cmd.stdout(Stdio::null()).stderr(Stdio::null()).spawn().unwrap_or_else(|e| panic!("{what}: {e}"))
    };
    let mut daemons = Daemons(Vec::new());
    daemons.0.push(spawn(
        Command::new(&munged)
            .arg("-F")
            .arg("--force")
            .arg(format!("--key-file={}", key.display()))
            .arg(format!("--socket={}", socket.display()))
            .arg(format!("--pid-file={}", dir.join("munge/munged.pid").display()))
            .arg(format!("--log-file={}", dir.join("munge/munged.log").display()))
            .arg(format!("--seed-file={}", dir.join("munge/munge.seed").display())),
        "munged",
    ));
    let deadline = Instant::now() + Duration::from_secs(20);
    while !socket.exists() {
        assert!(Instant::now() < deadline, "munged did not create its socket");
        std::thread::sleep(Duration::from_millis(100));
    }
    daemons.0.push(spawn(Command::new(&slurmctld).arg("-D").arg("-f").arg(&conf), "slurmctld"));
    daemons.0.push(spawn(Command::new(&slurmd).arg("-D").arg("-f").arg(&conf), "slurmd"));
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        let (ok, text) = output(Command::new(&sinfo).args(["-h", "-o", "%T"]).env("SLURM_CONF", &conf));
        if ok && text.trim() == "idle" {
            break;
        }
        if Instant::now() > deadline {
            let log = |f: &str| std::fs::read_to_string(dir.join(f)).unwrap_or_default();
            panic!(
                "the one-node cluster did not come up (sinfo: {text}); slurmctld.log:\n{}\nslurmd.log:\n{}",
                log("slurmctld.log"),
                log("slurmd.log")
            );
        }
        std::thread::sleep(Duration::from_millis(250));
    }
    let up = t0.elapsed().as_secs_f64();

    // The same sweep on this machine, then as a 4-task array with the template.
    let cases = sweep16_cases(&dir);
    let bin = env!("CARGO_BIN_EXE_harness");
    let args = format!("all --quick --cases {}", cases.display());
    let o = Command::new(bin).args(args.split(' ')).arg("--out").arg(dir.join("single")).output().unwrap();
    assert!(o.status.success(), "single machine: {}", String::from_utf8_lossy(&o.stderr));
    let t_array = Instant::now();
    let (ok, text) = output(
        Command::new("timeout")
            .arg("240")
            .arg(&sbatch)
            .args(["--wait", "--array=1-4", "--cpus-per-task=1"])
            .arg(format!("--output={}/out/task-%A_%a.out", dir.display()))
            .arg(root().join("cluster/flexmb-array.sbatch"))
            .env("SLURM_CONF", &conf)
            .env("HARNESS", bin)
            .env("FLEXMB_ARGS", &args)
            .env("FLEXMB_OUT", dir.join("shared"))
            .env("FLEXMB_DIR", &dir)
            .current_dir(&dir),
    );
    let tasks: Vec<String> = std::fs::read_dir(dir.join("out"))
        .unwrap()
        .filter_map(|e| std::fs::read_to_string(e.ok()?.path()).ok())
        .collect();
    assert!(ok, "sbatch --wait failed: {text}\ntask logs:\n{}", tasks.join("\n"));
    assert_eq!(tasks.len(), 4, "{text}");
    for k in 1..=4 {
        assert!(
            tasks.iter().any(|t| t.contains(&format!("all: shard {k} of 4: 4 of 16 units"))),
            "no task ran shard {k}:\n{}",
            tasks.join("\n")
        );
    }
    let array_s = t_array.elapsed().as_secs_f64();
    let o =
        Command::new(bin).arg("merge").arg(dir.join("shared")).arg("--out").arg(dir.join("merged")).output().unwrap();
    assert!(o.status.success(), "merge: {}", String::from_utf8_lossy(&o.stderr));
    let csvs = assert_same_report(&dir.join("single"), &dir.join("merged"));
    assert_eq!(csvs, 32);
    drop(daemons);
    eprintln!(
        "{TEST}: cluster up in {up:.1} s, 4-task array over 16 runs in {array_s:.1} s, {csvs} CSV files identical; \
         {:.1} s in all",
        t0.elapsed().as_secs_f64()
    );
    let _ = std::fs::remove_dir_all(&dir);
}
