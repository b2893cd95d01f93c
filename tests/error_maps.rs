//! `kiln verify --plot`'s error maps (issue 21, item 7): each error drawn where it is on the
//! table's axes, so that a picture shows where a table is wrong.

use kiln::integrate::reference::ReferenceSettings;
use kiln::verify::{Against, AuditSettings, audit, error_maps};
use kiln::{BakeOptions, Quantity};

/// One texel of an 8 x 8 `E` table spoiled by 0.1: the node map's worst cell is that texel's
/// (row = roughness index, column = mu index, on a nodes grid), holding 0.1, and the lookup
/// map's worst point is beside it.
#[test]
fn a_spoiled_texel_is_drawn_where_it_is() {
    let mut table = BakeOptions {
        quantities: vec![Quantity::E],
        size: 8,
        max_error: Some(1e-5),
        // Point samples on linear rows: each node's error is the spoil alone, at r = i / 7.
        mu_mapping: Some(kiln::MuMapping::Adaptive),
        ..BakeOptions::default()
    }
    .bake(&|_| {})
    .unwrap()
    .remove(0);
    let (row, column) = (5, 2);
    let k = row * 8 + column;
    table.value[k] -= 0.1;
    table.one_minus_value[k] += 0.1;
    let report = audit(
        &table,
        &Against::Reference(ReferenceSettings::default()),
        &AuditSettings::default(),
        &|_| {},
    );
    let maps = error_maps(&table.spec, &report);
    assert_eq!(maps.len(), 2);
    let nodes = &maps[0];
    assert_eq!((nodes.group, nodes.rows, nodes.columns), ("nodes", 8, 8));
    let worst_cell = nodes
        .cells
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.unwrap_or(0.0).total_cmp(&b.1.unwrap_or(0.0)))
        .unwrap();
    // Nodes at i / 7 fall in cells of width 1 / 8: node i in cell i.
    assert_eq!(worst_cell.0, row * 8 + column);
    assert!((worst_cell.1.unwrap() - 0.1).abs() < 1e-4, "{worst_cell:?}");
    // The roughness axis is perceptual r at nodes i / 7; the mu axis' coordinate likewise.
    let (x, y, error) = nodes.worst;
    assert!((y - row as f64 / 7.0).abs() < 1e-12 && (x - column as f64 / 7.0).abs() < 1e-9);
    assert!((error - 0.1).abs() < 1e-4);
    // The lookups' ladder (steps of 1 / 16) does not pass through the node: its worst point is
    // the nearest rung, where the bilinear weight of the spoiled node is still above a half.
    let lookups = &maps[1];
    assert_eq!((lookups.rows, lookups.columns), (17, 17));
    let (x, y, error) = lookups.worst;
    let step = 1.0 / 16.0;
    assert!((y - row as f64 / 7.0).abs() <= step && (x - column as f64 / 7.0).abs() <= step);
    assert!(error > 0.05 && error < 0.1 + 1e-3, "{error}");
    // Every cell of the node map holds a node.
    assert!(nodes.cells.iter().all(Option::is_some));
}

/// A 1-D table's map is one row along roughness.
#[test]
fn an_average_table_is_drawn_along_roughness() {
    let table = BakeOptions {
        quantities: vec![Quantity::EAvg],
        size: 8,
        max_error: Some(1e-5),
        // Point samples on linear rows: each node's error is the spoil alone, at r = i / 7.
        mu_mapping: Some(kiln::MuMapping::Adaptive),
        ..BakeOptions::default()
    }
    .bake(&|_| {})
    .unwrap()
    .remove(0);
    let report = audit(
        &table,
        &Against::Reference(ReferenceSettings::default()),
        &AuditSettings::default(),
        &|_| {},
    );
    let maps = error_maps(&table.spec, &report);
    assert_eq!((maps[0].rows, maps[0].columns), (1, 8));
    assert_eq!(maps[0].worst.1, 0.0);
    assert_eq!(maps[0].worst.0, report.worst_node.roughness);
}
