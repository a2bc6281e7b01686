//! A bone map: which joint of the model's skeleton each bone of the character follows. Read
//! from a YAML file (`character bone: model joint`), found by names, or found automatically
//! from the naming conventions both rigs follow; checked against both hierarchies.

use std::path::Path;

use super::conventions::{Convention, Role, recognise};
use crate::error::{FormatError, Part};

/// A rig's bones: their names and parents (indices into the same list).
#[derive(Debug, Clone, Copy)]
pub struct Rig<'a> {
    /// Each bone's name.
    pub names: &'a [String],
    /// Each bone's parent, `None` at a top.
    pub parents: &'a [Option<usize>],
}

impl Rig<'_> {
    /// Whether bone `above` is bone `below` or one of its ancestors.
    pub(crate) fn holds(&self, above: usize, below: usize) -> bool {
        let mut at = Some(below);
        let mut steps = 0;
        while let Some(n) = at {
            if n == above {
                return true;
            }
            steps += 1;
            if steps > self.parents.len() {
                return false;
            }
            at = self.parents[n];
        }
        false
    }

    /// How many ancestors bone `n` has.
    pub(crate) fn depth(&self, n: usize) -> usize {
        let mut depth = 0;
        let mut at = self.parents[n];
        while let Some(p) = at {
            depth += 1;
            if depth > self.parents.len() {
                break;
            }
            at = self.parents[p];
        }
        depth
    }

    /// The bones from the top down to bone `n`: sorted, these lists put bones depth first.
    fn path(&self, n: usize) -> Vec<usize> {
        let mut path = vec![n];
        let mut at = self.parents[n];
        while let Some(p) = at {
            if path.len() > self.parents.len() {
                break;
            }
            path.push(p);
            at = self.parents[p];
        }
        path.reverse();
        path
    }

    fn name_refs(&self) -> Vec<&str> {
        self.names.iter().map(String::as_str).collect()
    }
}

/// Which character bone follows which model joint: `(character bone, model joint)` name pairs,
/// in the character's order. Character bones it does not name keep their rest pose; model
/// joints it does not name are not shown.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct BoneMap {
    /// `(character bone, model joint)` pairs.
    pub pairs: Vec<(String, String)>,
}

impl BoneMap {
    /// Reads a map file: a YAML mapping of character bone names to model joint names.
    pub fn read(path: &Path) -> Result<BoneMap, FormatError> {
        let text = sinmdm::files::read_text_file(path, "a bone map").map_err(|reason| {
            FormatError::Io {
                path: path.to_path_buf(),
                reason,
            }
        })?;
        BoneMap::parse(&text).map_err(|message| FormatError::Unsupported {
            path: path.to_path_buf(),
            message,
        })
    }

    /// A map from its YAML text.
    pub fn parse(text: &str) -> Result<BoneMap, String> {
        let value: serde_yaml::Value = serde_yaml::from_str(text).map_err(|e| {
            format!("is not YAML ({e}); a bone map is lines of `character bone: model joint`")
        })?;
        let serde_yaml::Value::Mapping(mapping) = value else {
            return Err(
                "is not a YAML mapping; a bone map is lines of `character bone: model joint`"
                    .into(),
            );
        };
        let mut pairs = Vec::with_capacity(mapping.len());
        for (key, value) in mapping {
            let (Some(target), Some(source)) = (scalar(&key), scalar(&value)) else {
                return Err(format!(
                    "has an entry that is not `name: name` ({}: {})",
                    serde_yaml::to_string(&key).unwrap_or_default().trim(),
                    serde_yaml::to_string(&value).unwrap_or_default().trim()
                ));
            };
            pairs.push((target, source));
        }
        Ok(BoneMap { pairs })
    }

    /// The map as YAML, one `character bone: model joint` line each, with a header saying so.
    pub fn to_yaml(&self) -> String {
        let mut out = String::from(
            "# sinmdm bone map: each character bone (left) follows the model's joint (right).\n",
        );
        for (target, source) in &self.pairs {
            let mut one = serde_yaml::Mapping::new();
            one.insert(target.clone().into(), source.clone().into());
            out.push_str(&serde_yaml::to_string(&one).unwrap_or_default());
        }
        out
    }

    /// The map's pairs as bone indices of `target` and joint indices of `source`, checked:
    /// every name is a bone of its rig, and each character bone is named once.
    pub fn indices(
        &self,
        target: &Rig,
        source: &Rig,
        map: &Path,
    ) -> Result<Vec<(usize, usize)>, FormatError> {
        let find = |rig: &Rig, name: &str| rig.names.iter().position(|n| n == name);
        let bad = |name: &str, message: String| {
            FormatError::bad(map, Part::MapEntry(name.to_string()), message)
        };
        let mut pairs: Vec<(usize, usize)> = Vec::with_capacity(self.pairs.len());
        for (t, s) in &self.pairs {
            let b =
                find(target, t).ok_or_else(|| bad(t, "is not a bone of the character".into()))?;
            let j = find(source, s).ok_or_else(|| {
                bad(
                    t,
                    format!("follows '{s}', which is not a joint of the model"),
                )
            })?;
            if pairs.iter().any(|&(other, _)| other == b) {
                return Err(bad(t, "is named twice".into()));
            }
            pairs.push((b, j));
        }
        Ok(pairs)
    }

    /// The map of index pairs, by name, the character's bones chain by chain (depth first).
    pub fn of(pairs: &[(usize, usize)], target: &Rig, source: &Rig) -> BoneMap {
        let mut sorted = pairs.to_vec();
        sorted.sort_by_key(|&(b, _)| target.path(b));
        BoneMap {
            pairs: sorted
                .into_iter()
                .map(|(b, j)| (target.names[b].clone(), source.names[j].clone()))
                .collect(),
        }
    }
}

fn scalar(value: &serde_yaml::Value) -> Option<String> {
    match value {
        serde_yaml::Value::String(s) => Some(s.clone()),
        serde_yaml::Value::Number(n) => Some(n.to_string()),
        _ => None,
    }
}

/// Pairs by name: each model joint with the character bone of the same name, or else the one
/// bone whose name is it after a namespace (`mixamorig:Hips` for `Hips`).
pub fn pairs_by_name(target: &Rig, source: &Rig) -> Vec<(usize, usize)> {
    let mut pairs = Vec::new();
    for (j, joint) in source.names.iter().enumerate() {
        let exact = target.names.iter().position(|n| n == joint);
        let namespaced = || {
            let mut found = target
                .names
                .iter()
                .enumerate()
                .filter(|(_, n)| crate::sampled::without_namespace(n) == joint.as_str());
            match (found.next(), found.next()) {
                (Some((b, _)), None) => Some(b),
                _ => None,
            }
        };
        if let Some(b) = exact.or_else(namespaced) {
            pairs.push((b, j));
        }
    }
    pairs
}

/// An automatic map: both rigs' conventions recognised, and bones of the same role paired;
/// the chains (spine, neck) by their place along the chain.
#[derive(Debug, Clone, PartialEq)]
pub struct AutoMap {
    /// `(character bone, model joint)` index pairs.
    pub pairs: Vec<(usize, usize)>,
    /// The character's convention.
    pub target: Convention,
    /// The model's convention.
    pub source: Convention,
}

/// Pairs the rigs' bones by role, or says which rig follows no known convention.
pub fn pairs_by_role(target: &Rig, source: &Rig) -> Result<AutoMap, String> {
    let unknown = |which: &str| {
        format!(
            "the {which}'s bone names follow no convention known here (Mixamo, CMU BVH, Unreal mannequin, Unity Humanoid, Rigify DEF-); write a bone map and pass it as --retarget MAP.yaml"
        )
    };
    let t = recognise(&target.name_refs()).ok_or_else(|| unknown("character"))?;
    let s = recognise(&source.name_refs()).ok_or_else(|| unknown("model"))?;
    let bones_of = |roles: &[Option<Role>], rig: &Rig, role: Role| -> Vec<usize> {
        let mut bones: Vec<usize> = (0..roles.len())
            .filter(|&n| roles[n] == Some(role))
            .collect();
        bones.sort_by_key(|&n| rig.depth(n));
        bones
    };
    let mut pairs = Vec::new();
    let mut roles: Vec<Role> = Vec::new();
    for role in t.roles.iter().flatten() {
        if !roles.contains(role) {
            roles.push(*role);
        }
    }
    for role in roles {
        let ours = bones_of(&t.roles, target, role);
        let theirs = bones_of(&s.roles, source, role);
        if theirs.is_empty() {
            continue;
        }
        // Along a chain: bone i of n follows the source bone at the same place.
        for (i, &b) in ours.iter().enumerate() {
            let at = ((i as f64 + 0.5) * theirs.len() as f64 / ours.len() as f64) as usize;
            pairs.push((b, theirs[at.min(theirs.len() - 1)]));
        }
    }
    fill_between(&mut pairs, target, source);
    pairs.sort_unstable();
    Ok(AutoMap {
        pairs,
        target: t.convention,
        source: s.convention,
    })
}

/// Pairs the unnamed bones that sit alone between two paired ones on both rigs (a CMU clip's
/// `LHipJoint` between the hips and the thigh, and the character's own bone there), so a joint
/// that turns in the clip turns on the character too.
fn fill_between(pairs: &mut Vec<(usize, usize)>, target: &Rig, source: &Rig) {
    let paired =
        |pairs: &[(usize, usize)], b: usize| pairs.iter().find(|&&(t, _)| t == b).map(|&(_, j)| j);
    loop {
        let mut added = None;
        for (b, parent) in target.parents.iter().enumerate() {
            if paired(pairs, b).is_some() {
                continue;
            }
            let Some(above) = parent.and_then(|p| paired(pairs, p)) else {
                continue;
            };
            let children: Vec<usize> = (0..target.parents.len())
                .filter(|&c| target.parents[c] == Some(b))
                .collect();
            let [child] = children.as_slice() else {
                continue;
            };
            let Some(below) = paired(pairs, *child) else {
                continue;
            };
            // The source joint between: the parent of `below`, itself a child of `above`.
            let Some(between) = source.parents[below] else {
                continue;
            };
            let unpaired = !pairs.iter().any(|&(_, j)| j == between);
            if between != above && source.parents[between] == Some(above) && unpaired {
                added = Some((b, between));
                break;
            }
        }
        match added {
            Some(pair) => pairs.push(pair),
            None => return,
        }
    }
}

/// Checks that `pairs` keep both hierarchies: the nearest paired ancestor of each paired
/// character bone follows a model joint at or above the bone's own, so no chain is broken or
/// turned round. Names the first bone that breaks one.
pub fn check_chains(pairs: &[(usize, usize)], target: &Rig, source: &Rig) -> Result<(), String> {
    for &(b, j) in pairs {
        let mut at = target.parents[b];
        let mut steps = 0;
        while let Some(a) = at {
            if let Some(&(_, i)) = pairs.iter().find(|&&(t, _)| t == a) {
                if !source.holds(i, j) {
                    return Err(format!(
                        "the map breaks a chain at '{}': it follows '{}', which is not below '{}', followed by its ancestor '{}'",
                        target.names[b], source.names[j], source.names[i], target.names[a]
                    ));
                }
                break;
            }
            steps += 1;
            if steps > target.parents.len() {
                break;
            }
            at = target.parents[a];
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rig(spec: &[(&str, Option<usize>)]) -> (Vec<String>, Vec<Option<usize>>) {
        (
            spec.iter().map(|(n, _)| n.to_string()).collect(),
            spec.iter().map(|(_, p)| *p).collect(),
        )
    }

    fn rig_of(bones: &(Vec<String>, Vec<Option<usize>>)) -> Rig<'_> {
        Rig {
            names: &bones.0,
            parents: &bones.1,
        }
    }

    fn cmu() -> (Vec<String>, Vec<Option<usize>>) {
        rig(&[
            ("Hips", None),
            ("LHipJoint", Some(0)),
            ("LeftUpLeg", Some(1)),
            ("LeftLeg", Some(2)),
            ("LeftFoot", Some(3)),
            ("RHipJoint", Some(0)),
            ("RightUpLeg", Some(5)),
            ("RightLeg", Some(6)),
            ("RightFoot", Some(7)),
            ("LowerBack", Some(0)),
            ("Spine", Some(9)),
            ("Spine1", Some(10)),
            ("Neck", Some(11)),
            ("Neck1", Some(12)),
            ("Head", Some(13)),
        ])
    }

    fn unreal() -> (Vec<String>, Vec<Option<usize>>) {
        rig(&[
            ("root", None),
            ("pelvis", Some(0)),
            ("spine_01", Some(1)),
            ("spine_02", Some(2)),
            ("neck_01", Some(3)),
            ("head", Some(4)),
            ("thigh_l", Some(1)),
            ("calf_l", Some(6)),
            ("foot_l", Some(7)),
            ("thigh_r", Some(1)),
            ("calf_r", Some(9)),
            ("foot_r", Some(10)),
        ])
    }

    #[test]
    fn an_unreal_mannequin_follows_a_cmu_clip_by_role() {
        let (unreal, cmu) = (unreal(), cmu());
        let (target, source) = (rig_of(&unreal), rig_of(&cmu));
        let found = pairs_by_role(&target, &source).unwrap();
        assert_eq!(found.target, Convention::Unreal);
        assert_eq!(found.source, Convention::CmuBvh);
        let map = BoneMap::of(&found.pairs, &target, &source);
        let expected = [
            ("pelvis", "Hips"),
            ("spine_01", "LowerBack"),
            ("spine_02", "Spine1"),
            ("neck_01", "Neck1"),
            ("head", "Head"),
            ("thigh_l", "LeftUpLeg"),
            ("calf_l", "LeftLeg"),
            ("foot_l", "LeftFoot"),
            ("thigh_r", "RightUpLeg"),
            ("calf_r", "RightLeg"),
            ("foot_r", "RightFoot"),
        ];
        let got: Vec<(&str, &str)> = map
            .pairs
            .iter()
            .map(|(a, b)| (a.as_str(), b.as_str()))
            .collect();
        assert_eq!(got, expected);
        check_chains(&found.pairs, &target, &source).unwrap();
        // Its YAML reads back as the same map.
        assert_eq!(BoneMap::parse(&map.to_yaml()).unwrap(), map);
    }

    #[test]
    fn a_map_that_turns_a_chain_round_is_refused_naming_the_bone() {
        let (unreal, cmu) = (unreal(), cmu());
        let (target, source) = (rig_of(&unreal), rig_of(&cmu));
        let map = BoneMap::parse("pelvis: Hips\nthigh_l: LeftLeg\ncalf_l: LeftUpLeg\n").unwrap();
        let pairs = map
            .indices(&target, &source, Path::new("map.yaml"))
            .unwrap();
        let err = check_chains(&pairs, &target, &source).unwrap_err();
        assert!(
            err.contains("'calf_l'") && err.contains("'LeftUpLeg'"),
            "{err}"
        );
    }

    #[test]
    fn a_map_naming_a_missing_bone_says_which() {
        let (unreal, cmu) = (unreal(), cmu());
        let (target, source) = (rig_of(&unreal), rig_of(&cmu));
        let map = BoneMap::parse("pelvis: Hips\nthigh_left: LeftUpLeg\n").unwrap();
        let err = map
            .indices(&target, &source, Path::new("map.yaml"))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("map.yaml") && err.contains("'thigh_left'"),
            "{err}"
        );
        let map = BoneMap::parse("pelvis: Pelvis\n").unwrap();
        let err = map
            .indices(&target, &source, Path::new("map.yaml"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("'Pelvis'"), "{err}");
        assert!(BoneMap::parse("- a\n- b\n").is_err());
    }
}
