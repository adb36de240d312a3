//! The mesh friction option at the interfaces: its JSON names (every model's name parses and
//! round-trips).

use helical_gear_mesh::mesh::{Friction, FrictionModel};

#[test]
fn every_model_name_parses_and_round_trips() {
    for model in [FrictionModel::None, FrictionModel::Constant, FrictionModel::IsoTr14179_2] {
        let text = format!("{{\"model\": \"{}\"}}", model.name());
        let f = Friction::from_json(&text).unwrap_or_else(|e| panic!("{text}: {e}"));
        assert_eq!(f.model, model);
        assert_eq!(Friction::from_json(&f.to_json()).unwrap(), f);
    }
    assert_eq!(Friction::from_json("none").unwrap(), Friction::none());
    assert_eq!(Friction::from_json("").unwrap(), Friction::none());
}
