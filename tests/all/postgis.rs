//! A real PostGIS source: a throw-away PostgreSQL cluster on loopback holds
//! the training islands (loaded with `ogr2ogr`), and a pipeline reads them
//! through a `PG:` connection string with a `where` clause; the output can
//! never be written into that database.
//!
//! Needs the Debian packages `postgresql` and `postgis` (`.ci/run` installs
//! them). Without them the test says so and passes, unless
//! `SKELETONISE_REQUIRE_POSTGIS` is set (as CI sets it).

use crate::common::*;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A PostgreSQL cluster in a temporary directory, stopped and removed on drop.
struct Cluster {
    dir: tempfile::TempDir,
    bin: PathBuf,
    port: u16,
}

fn is_root() -> bool {
    // SAFETY: geteuid has no preconditions.
    unsafe { libc::geteuid() == 0 }
}

fn as_postgres(cmd: &Path) -> Command {
    // initdb refuses to run as root: run the server as `postgres` then.
    if is_root() {
        let mut c = Command::new("runuser");
        c.args(["-u", "postgres", "--"]).arg(cmd);
        c
    } else {
        Command::new(cmd)
    }
}

impl Cluster {
    fn start() -> Option<Self> {
        let bin = std::fs::read_dir("/usr/lib/postgresql")
            .ok()?
            .flatten()
            .map(|e| e.path().join("bin"))
            .filter(|b| b.join("initdb").exists())
            .max()?;
        let dir = tempfile::tempdir().ok()?;
        if is_root() {
            Command::new("chown")
                .args(["postgres:", dir.path().to_str()?])
                .status()
                .ok()?;
        }
        let port = std::net::TcpListener::bind("127.0.0.1:0")
            .ok()?
            .local_addr()
            .ok()?
            .port();
        let data = dir.path().join("data");
        let ok = as_postgres(&bin.join("initdb"))
            .args(["-D", data.to_str()?, "-U", "postgres", "-A", "trust"])
            .output()
            .ok()?
            .status
            .success();
        assert!(ok, "initdb failed");
        let opts = format!(
            "-c listen_addresses=127.0.0.1 -p {port} -k {}",
            dir.path().display()
        );
        let ok = as_postgres(&bin.join("pg_ctl"))
            .args([
                "-D",
                data.to_str()?,
                "-l",
                dir.path().join("log").to_str()?,
                "-w",
                "-o",
                &opts,
                "start",
            ])
            .output()
            .ok()?
            .status
            .success();
        assert!(ok, "the server did not start");
        Some(Self { dir, bin, port })
    }

    fn conn(&self, db: &str) -> String {
        format!(
            "PG:host=127.0.0.1 port={} dbname={db} user=postgres",
            self.port
        )
    }

    fn psql(&self, db: &str, sql: &str) -> String {
        let o = Command::new("psql")
            .args([
                "-h",
                "127.0.0.1",
                "-p",
                &self.port.to_string(),
                "-U",
                "postgres",
                "-d",
                db,
                "-qAtc",
                sql,
            ])
            .output()
            .expect("psql runs");
        assert!(
            o.status.success(),
            "{sql}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        String::from_utf8_lossy(&o.stdout).trim().to_string()
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        let data = self.dir.path().join("data");
        let _ = as_postgres(&self.bin.join("pg_ctl"))
            .args([
                "-D",
                data.to_str().unwrap_or_default(),
                "-m",
                "immediate",
                "stop",
            ])
            .output();
    }
}

#[test]
fn a_postgis_source_with_a_where_clause_and_never_an_output_into_it() {
    let Some(pg) = Cluster::start() else {
        let required = std::env::var_os("SKELETONISE_REQUIRE_POSTGIS").is_some();
        assert!(
            !required,
            "PostgreSQL is not installed: apt-get install postgresql postgis"
        );
        eprintln!("skipped: PostgreSQL is not installed (apt-get install postgresql postgis)");
        return;
    };
    pg.psql("postgres", "CREATE DATABASE gis");
    pg.psql("gis", "CREATE EXTENSION postgis");
    let load = Command::new("ogr2ogr")
        .args([
            "-f",
            "PostgreSQL",
            &pg.conn("gis"),
            &root(TRAIN),
            "islands_hebrides",
            "-nln",
            "islands",
        ])
        .output()
        .expect("ogr2ogr runs");
    assert!(
        load.status.success(),
        "{}",
        String::from_utf8_lossy(&load.stderr)
    );
    let want: u64 = pg
        .psql("gis", "SELECT count(*) FROM islands WHERE area_m2 > 1e6")
        .parse()
        .unwrap();
    assert!(want > 10, "{want}");
    let d = tmp();
    let out = d.path().join("from-postgis.gpkg");
    let o = skeletonise(&[
        "run",
        "pipelines/islands.yaml",
        "-i",
        &pg.conn("gis"),
        "--set",
        "input.layer=islands",
        "--set",
        "input.where=area_m2 > 1e6",
        "-o",
        out.to_str().unwrap(),
    ]);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 0, "{err}");
    let ds = open(&out);
    assert_eq!(count(&ds, "skeletons"), want);
    assert_eq!(count(&ds, "rejected"), 0);
    let methods = strings(&ds, "skeletons", "method");
    assert!(methods.iter().all(Option::is_some));
    // A bad filter on the database is an error, not an empty success.
    let o = skeletonise(&[
        "run",
        "pipelines/islands.yaml",
        "-i",
        &pg.conn("gis"),
        "--set",
        "input.layer=islands",
        "--set",
        "input.where=no_such_column > 1",
        "-o",
        d.path().join("x.gpkg").to_str().unwrap(),
    ]);
    assert_eq!(code_and_err(&o).0, 1, "{}", code_and_err(&o).1);
    // The output can never go into the database it reads.
    let o = skeletonise(&[
        "run",
        "pipelines/islands.yaml",
        "-i",
        &pg.conn("gis"),
        "--set",
        "input.layer=islands",
        "-o",
        &pg.conn("gis"),
    ]);
    let (code, err) = code_and_err(&o);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains(".gpkg"), "{err}");
    assert_eq!(pg.psql("gis", "SELECT count(*) FROM information_schema.tables WHERE table_schema = 'public' AND table_name NOT IN ('islands', 'spatial_ref_sys', 'geography_columns', 'geometry_columns')"), "0");
}
