//! `helical-gear`: command-line front end of the helical_gear_mesh library.
fn main() {
    let p = helical_gear_mesh::GearPair::paper_table1();
    println!("{}", serde_json::to_string_pretty(&p).unwrap());
}
