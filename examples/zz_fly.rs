use fuzzyvox::fly::*;
use fuzzyvox::sim::scenario;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let which = args.get(1).map(String::as_str).unwrap_or("random");
    let seed: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1);
    let n: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(3);
    let sc = if which == "wall" {
        scenario::wall().unwrap()
    } else {
        scenario::random(10, seed).unwrap()
    };
    let config = FlyConfig::default();
    let t = std::time::Instant::now();
    let goals = draw_goals(&sc, &config, n, seed).unwrap();
    eprintln!("goals {} in {:.1}s", goals.len(), t.elapsed().as_secs_f64());
    for g in &goals {
        eprintln!(
            "  {:?} -> {:?} truth {:.1}",
            g.start.coords.as_slice(),
            g.goal.coords.as_slice(),
            g.truth_length
        );
    }
    let models: Vec<FlyModel> = match args.get(4).map(String::as_str) {
        Some("fuzzy") => vec![FlyModel::Fuzzy],
        _ => FlyModel::ALL.to_vec(),
    };
    let out = fly_all(&sc, &goals, &models, &config, seed, false, &mut |d, t| {
        eprint!("\r{d}/{t}")
    })
    .unwrap();
    eprintln!();
    for m in &out {
        for f in &m.flights {
            eprintln!(
                "{:?} {:?} len {:.1} frames {} depth {} refused {} replans {}",
                m.model, f.ending, f.length, f.frames, f.depth_images, f.depth_refused, f.replans
            );
        }
        println!("{}", serde_json::to_string(&m.summary(&goals)).unwrap());
    }
    eprintln!("total {:.1}s", t.elapsed().as_secs_f64());
}
#[allow(dead_code)]
fn dbg_goal() {}
