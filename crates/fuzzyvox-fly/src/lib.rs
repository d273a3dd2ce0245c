//! The vehicle of closed-loop flights: a simulated drone with one camera flies to a goal
//! through a scene it has not seen, mapping as it goes. Every cycle it plans through what its
//! map knows, advances a little, takes a picture, estimates depth from its own motion (poor
//! when it flies towards what it looks at), updates the map and replans; the true scene checks
//! every step.
//!
//! - [`config`]: the loop's parameters ([`FlyConfig`]);
//! - [`region`]: the box a flight plans in;
//! - [`guard`]: no unseen space near the vehicle ([`UnknownGuard`]);
//! - [`flight`]: one flight ([`Flight`], [`fly_goal`]) and the prior map around the start.
//!
//! Where flights go, flying every goal with every map, and the reports are the experiment
//! layer's (`fuzzyvox_eval::closed_loop`).

pub mod config;
pub mod flight;
pub mod guard;
pub mod region;

pub use config::FlyConfig;
pub use flight::{
    CycleTimes, Ending, Flight, FlightLog, LOOK_FRAMES, REACHED_VOXELS, STALL_FRAMES, VIEW_MARGIN,
    fly_goal, integrate_prior,
};
pub use guard::UnknownGuard;
pub use region::planning_region;
