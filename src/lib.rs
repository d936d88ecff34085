//! `grains`: granular dynamics (DEM) of spherical grains.
//!
//! A scene ([`scene`]) is validated into SI units, an engine ([`cpu`]) advances it with the
//! contact laws of [`model`], and the host loop ([`protocol`]) drives stages and records
//! statistics and frames ([`output`]).

pub mod analysis;
pub mod cd;
pub mod bench;
pub mod checkpoint;
pub mod compare;
pub mod cpu;
pub mod engine;
pub mod flow;
pub mod gpu;
pub mod lammps;
pub mod mesh;
pub mod model;
pub mod output;
pub mod periodic;
pub mod position;
pub mod protocol;
pub mod real;
pub mod runner;
pub mod schedule;
pub mod scene;
pub mod state;
pub mod sweep;
pub mod timestep;
pub mod turn;
pub mod walls;
pub mod workgroup;
