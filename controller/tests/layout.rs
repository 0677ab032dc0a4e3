//! The controller's modules form no cycle (issue 22: intake apart from the update, the
//! configuration on its own; docs/controller.md, "Which module uses which"). An edge is
//! any `crate::name` outside a comment in a top-level module's files (tests of a file's
//! own `mod tests` left out); a cycle is found by depth-first search.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Top-level module -> the top-level modules its code names.
fn module_graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    let mut stack = vec![src.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).expect("controller/src is readable") {
            let path = entry.expect("a directory entry").path();
            if path.is_dir() {
                stack.push(path);
                continue;
            }
            let rel = path.strip_prefix(src).expect("below src");
            let first = rel.components().next().expect("a component");
            let top = first
                .as_os_str()
                .to_string_lossy()
                .trim_end_matches(".rs")
                .to_string();
            if top == "lib" || path.extension().is_none_or(|e| e != "rs") {
                continue;
            }
            let text = std::fs::read_to_string(&path).expect("a source file");
            let code = text.split("#[cfg(test)]\nmod tests").next().unwrap_or("");
            let names = graph.entry(top.clone()).or_default();
            for line in code.lines().filter(|l| !l.trim_start().starts_with("//")) {
                for (i, _) in line.match_indices("crate::") {
                    let name: String = line[i + 7..]
                        .chars()
                        .take_while(|c| c.is_ascii_lowercase() || *c == '_')
                        .collect();
                    if !name.is_empty() && name != top {
                        names.insert(name);
                    }
                }
            }
        }
    }
    graph
}

/// A cycle through `node`, if the search from it finds one (as the path around it).
fn find_cycle(
    graph: &BTreeMap<String, BTreeSet<String>>,
    node: &str,
    path: &mut Vec<String>,
    done: &mut BTreeSet<String>,
) -> Option<Vec<String>> {
    if let Some(at) = path.iter().position(|n| n == node) {
        let mut cycle = path[at..].to_vec();
        cycle.push(node.to_string());
        return Some(cycle);
    }
    if done.contains(node) {
        return None;
    }
    path.push(node.to_string());
    for next in graph.get(node).into_iter().flatten() {
        if graph.contains_key(next) {
            if let Some(c) = find_cycle(graph, next, path, done) {
                return Some(c);
            }
        }
    }
    path.pop();
    done.insert(node.to_string());
    None
}

fn cycle_in(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    let mut done = BTreeSet::new();
    graph
        .keys()
        .find_map(|n| find_cycle(graph, n, &mut Vec::new(), &mut done))
}

#[test]
fn the_modules_form_no_cycle() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let graph = module_graph(&src);
    // The walk saw the modules that matter, with their edges.
    for (module, uses) in [
        ("intake", "control"),
        ("update", "control"),
        ("nav", "fault"),
    ] {
        assert!(
            graph[module].contains(uses),
            "{module} -> {uses}: {graph:?}"
        );
    }
    assert_eq!(cycle_in(&graph), None, "{graph:#?}");
}

/// The search finds a cycle when there is one: `control` naming `intake` back.
#[test]
fn a_cycle_is_found() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut graph = module_graph(&src);
    graph.get_mut("control").unwrap().insert("intake".into());
    let cycle = cycle_in(&graph).expect("control -> intake -> control");
    assert_eq!(cycle.first(), cycle.last());
    assert!(cycle.contains(&"intake".to_string()) && cycle.contains(&"control".to_string()));
}
