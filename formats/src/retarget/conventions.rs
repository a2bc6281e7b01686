//! The bone naming conventions users' rigs follow, and the body part each name stands for: how
//! an automatic bone map pairs a Mixamo character with a CMU clip or an Unreal mannequin.

use std::fmt;

/// A side of the body.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Side {
    /// The character's left.
    Left,
    /// The character's right.
    Right,
}

/// The body part a bone stands for. The spine and the neck are chains: a rig has one bone or
/// several for each.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Role {
    /// The pelvis, the bone that carries the body.
    Hips,
    /// A bone of the spine between the hips and the neck.
    Spine,
    /// A bone of the neck.
    Neck,
    /// The head.
    Head,
    /// The clavicle.
    Shoulder(Side),
    /// The upper arm.
    UpperArm(Side),
    /// The forearm.
    LowerArm(Side),
    /// The hand.
    Hand(Side),
    /// The thigh.
    UpperLeg(Side),
    /// The shin.
    LowerLeg(Side),
    /// The foot.
    Foot(Side),
    /// The toes (the ball of the foot).
    Toes(Side),
}

/// A naming convention.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Convention {
    /// Mixamo's `mixamorig:` rigs, with any namespace or none.
    Mixamo,
    /// The CMU motion capture database's BVH exports (`LowerBack`, `LHipJoint`, `Neck1`).
    CmuBvh,
    /// BVH exports named by joints rather than bones (`LeftHip`, `LeftKnee`, `LeftCollar`,
    /// `LeftShoulder` for the upper arm, `lowerback`, `Chest`).
    JointNamedBvh,
    /// Unreal's mannequin (`pelvis`, `spine_01`, `thigh_l`).
    Unreal,
    /// Unity's Humanoid avatar names (`LeftUpperLeg`, `Chest`).
    UnityHumanoid,
    /// Blender Rigify's deform bones (`DEF-spine`, `DEF-thigh.L`).
    Rigify,
}

impl Convention {
    /// Every convention, in the order ties are broken.
    pub const ALL: [Convention; 6] = [
        Convention::Mixamo,
        Convention::CmuBvh,
        Convention::JointNamedBvh,
        Convention::Unreal,
        Convention::UnityHumanoid,
        Convention::Rigify,
    ];

    /// The convention's name as users know it.
    pub fn name(self) -> &'static str {
        match self {
            Convention::Mixamo => "Mixamo",
            Convention::CmuBvh => "CMU BVH",
            Convention::JointNamedBvh => "joint-named BVH",
            Convention::Unreal => "Unreal mannequin",
            Convention::UnityHumanoid => "Unity Humanoid",
            Convention::Rigify => "Rigify (DEF-)",
        }
    }

    /// The plain names (see [`plain_name`]) of each role; `{side}` stands for `left`/`right`,
    /// `{s}` for `l`/`r`.
    fn table(self) -> &'static [(Part, &'static [&'static str])] {
        use Part::*;
        match self {
            Convention::Mixamo => &[
                (Hips, &["hips"]),
                (Spine, &["spine", "spine1", "spine2", "spine3"]),
                (Neck, &["neck", "neck1"]),
                (Head, &["head"]),
                (Shoulder, &["{side}shoulder"]),
                (UpperArm, &["{side}arm"]),
                (LowerArm, &["{side}forearm"]),
                (Hand, &["{side}hand"]),
                (UpperLeg, &["{side}upleg"]),
                (LowerLeg, &["{side}leg"]),
                (Foot, &["{side}foot"]),
                (Toes, &["{side}toebase"]),
            ],
            Convention::CmuBvh => &[
                (Hips, &["hips"]),
                (Spine, &["lowerback", "spine", "spine1"]),
                (Neck, &["neck", "neck1"]),
                (Head, &["head"]),
                (Shoulder, &["{side}shoulder"]),
                (UpperArm, &["{side}arm"]),
                (LowerArm, &["{side}forearm"]),
                (Hand, &["{side}hand"]),
                (UpperLeg, &["{side}upleg"]),
                (LowerLeg, &["{side}leg"]),
                (Foot, &["{side}foot"]),
                (Toes, &["{side}toebase"]),
                (Unused, &["{s}hipjoint", "{side}fingerbase", "{s}thumb"]),
            ],
            Convention::JointNamedBvh => &[
                (Hips, &["hips"]),
                (Spine, &["lowerback", "chest", "chest2", "chest3", "chest4"]),
                (Neck, &["lowerneck", "neck", "upperneck"]),
                (Head, &["head"]),
                (Shoulder, &["{side}collar"]),
                (UpperArm, &["{side}shoulder"]),
                (LowerArm, &["{side}elbow"]),
                (Hand, &["{side}wrist"]),
                (UpperLeg, &["{side}hip"]),
                (LowerLeg, &["{side}knee"]),
                (Foot, &["{side}ankle"]),
                (Toes, &["{side}toe"]),
                (
                    Unused,
                    &["{s}hipjoint", "{s}hand", "{s}fingers", "{s}thumb"],
                ),
            ],
            Convention::Unreal => &[
                (Hips, &["pelvis"]),
                (
                    Spine,
                    &["spine01", "spine02", "spine03", "spine04", "spine05"],
                ),
                (Neck, &["neck01", "neck02"]),
                (Head, &["head"]),
                (Shoulder, &["clavicle{s}"]),
                (UpperArm, &["upperarm{s}"]),
                (LowerArm, &["lowerarm{s}"]),
                (Hand, &["hand{s}"]),
                (UpperLeg, &["thigh{s}"]),
                (LowerLeg, &["calf{s}"]),
                (Foot, &["foot{s}"]),
                (Toes, &["ball{s}"]),
            ],
            Convention::UnityHumanoid => &[
                (Hips, &["hips"]),
                (Spine, &["spine", "chest", "upperchest"]),
                (Neck, &["neck"]),
                (Head, &["head"]),
                (Shoulder, &["{side}shoulder"]),
                (UpperArm, &["{side}upperarm"]),
                (LowerArm, &["{side}lowerarm"]),
                (Hand, &["{side}hand"]),
                (UpperLeg, &["{side}upperleg"]),
                (LowerLeg, &["{side}lowerleg"]),
                (Foot, &["{side}foot"]),
                (Toes, &["{side}toes"]),
            ],
            Convention::Rigify => &[
                (Hips, &["defspine"]),
                (Spine, &["defspine001", "defspine002", "defspine003"]),
                (Neck, &["defspine004", "defspine005"]),
                (Head, &["defspine006"]),
                (Shoulder, &["defshoulder{s}"]),
                (UpperArm, &["defupperarm{s}"]),
                (LowerArm, &["defforearm{s}"]),
                (Hand, &["defhand{s}"]),
                (UpperLeg, &["defthigh{s}"]),
                (LowerLeg, &["defshin{s}"]),
                (Foot, &["deffoot{s}"]),
                (Toes, &["deftoe{s}"]),
            ],
        }
    }

    /// The role of a bone named `name` in this convention, if it has one (`Ok(None)`: a name
    /// the convention knows but maps to no role; `Err(())`: a name it does not know).
    fn role_of(self, name: &str) -> Result<Option<Role>, ()> {
        let plain = plain_name(name);
        for (part, patterns) in self.table() {
            for pattern in *patterns {
                for side in [Side::Left, Side::Right] {
                    let (long, short) = match side {
                        Side::Left => ("left", "l"),
                        Side::Right => ("right", "r"),
                    };
                    let sided = pattern.contains('{');
                    let expected = pattern.replace("{side}", long).replace("{s}", short);
                    if expected == plain {
                        return Ok(part.role(side));
                    }
                    if !sided {
                        break;
                    }
                }
            }
        }
        Err(())
    }
}

impl fmt::Display for Convention {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A role before its side is known (the tables' rows).
#[derive(Debug, Clone, Copy)]
enum Part {
    Hips,
    Spine,
    Neck,
    Head,
    Shoulder,
    UpperArm,
    LowerArm,
    Hand,
    UpperLeg,
    LowerLeg,
    Foot,
    Toes,
    /// Names the convention has that stand for no role (they count towards recognising it).
    Unused,
}

impl Part {
    fn role(self, side: Side) -> Option<Role> {
        Some(match self {
            Part::Hips => Role::Hips,
            Part::Spine => Role::Spine,
            Part::Neck => Role::Neck,
            Part::Head => Role::Head,
            Part::Shoulder => Role::Shoulder(side),
            Part::UpperArm => Role::UpperArm(side),
            Part::LowerArm => Role::LowerArm(side),
            Part::Hand => Role::Hand(side),
            Part::UpperLeg => Role::UpperLeg(side),
            Part::LowerLeg => Role::LowerLeg(side),
            Part::Foot => Role::Foot(side),
            Part::Toes => Role::Toes(side),
            Part::Unused => return None,
        })
    }
}

/// A bone's name as the tables spell it: without a namespace (`mixamorig:`, `Armature|`) or
/// Mixamo's prefix written without one (`mixamorig_`, `mixamorig1_`), lower case, letters and
/// digits only (`DEF-thigh.L` is `defthighl`, `spine_01` is `spine01`).
pub fn plain_name(name: &str) -> String {
    let base = name.rsplit([':', '|']).next().unwrap_or(name);
    let lower = base.to_ascii_lowercase();
    let mut rest = lower.as_str();
    if let Some(after) = rest.strip_prefix("mixamorig") {
        rest = after.trim_start_matches(|c: char| c.is_ascii_digit());
    }
    rest.chars().filter(char::is_ascii_alphanumeric).collect()
}

/// A rig's bones recognised in one convention: each bone's role, `None` for bones it does not
/// stand for.
#[derive(Debug, Clone, PartialEq)]
pub struct Recognised {
    /// The convention.
    pub convention: Convention,
    /// Per bone, its role.
    pub roles: Vec<Option<Role>>,
    /// How many bones' names the convention knows.
    pub known: usize,
}

/// The fewest roles a rig must show for a convention to count as recognised: hips, a spine, a
/// head and both legs' thighs and shins.
const FEWEST_ROLES: usize = 7;

/// The convention that knows the most of `names` (ties: [`Convention::ALL`]'s order), when it
/// finds the hips and at least [`FEWEST_ROLES`] roles; a role claimed by two bones keeps the
/// first, except the chains (spine, neck).
pub fn recognise(names: &[&str]) -> Option<Recognised> {
    let mut best: Option<Recognised> = None;
    for convention in Convention::ALL {
        let mut roles: Vec<Option<Role>> = Vec::with_capacity(names.len());
        let mut known = 0;
        for name in names {
            let role = match convention.role_of(name) {
                Ok(role) => {
                    known += 1;
                    role
                }
                Err(()) => None,
            };
            let taken = role.is_some_and(|r| {
                !matches!(r, Role::Spine | Role::Neck) && roles.contains(&Some(r))
            });
            roles.push(if taken { None } else { role });
        }
        let mut distinct: Vec<Role> = Vec::new();
        for role in roles.iter().flatten() {
            if !distinct.contains(role) {
                distinct.push(*role);
            }
        }
        if distinct.len() < FEWEST_ROLES || !roles.contains(&Some(Role::Hips)) {
            continue;
        }
        if best.as_ref().is_none_or(|b| known > b.known) {
            best = Some(Recognised {
                convention,
                roles,
                known,
            });
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plain_names_drop_namespaces_prefixes_and_separators() {
        assert_eq!(plain_name("mixamorig:LeftUpLeg"), "leftupleg");
        assert_eq!(plain_name("mixamorig1_Hips"), "hips");
        assert_eq!(plain_name("DEF-thigh.L"), "defthighl");
        assert_eq!(plain_name("spine_01"), "spine01");
        assert_eq!(plain_name("Armature|Hips"), "hips");
    }

    fn names(list: &str) -> Vec<&str> {
        list.split_whitespace().collect()
    }

    #[test]
    fn each_convention_is_recognised_from_its_own_names() {
        let rigs = [
            (
                Convention::Mixamo,
                "mixamorig:Hips mixamorig:Spine mixamorig:Spine1 mixamorig:Spine2 mixamorig:Neck mixamorig:Head mixamorig:LeftUpLeg mixamorig:LeftLeg mixamorig:LeftFoot mixamorig:RightUpLeg mixamorig:RightLeg mixamorig:RightFoot",
            ),
            (
                Convention::CmuBvh,
                "Hips LHipJoint LeftUpLeg LeftLeg LeftFoot RHipJoint RightUpLeg RightLeg RightFoot LowerBack Spine Spine1 Neck Neck1 Head",
            ),
            (
                Convention::JointNamedBvh,
                "Hips LHipJoint LeftHip LeftKnee LeftAnkle LeftToe RHipJoint RightHip RightKnee RightAnkle lowerback Chest Chest2 lowerneck Neck Head LeftCollar LeftShoulder LeftElbow",
            ),
            (
                Convention::Unreal,
                "root pelvis spine_01 spine_02 spine_03 neck_01 head thigh_l calf_l foot_l ball_l thigh_r calf_r foot_r ball_r clavicle_l upperarm_l",
            ),
            (
                Convention::UnityHumanoid,
                "Hips Spine Chest UpperChest Neck Head LeftUpperLeg LeftLowerLeg LeftFoot LeftToes RightUpperLeg RightLowerLeg RightFoot",
            ),
            (
                Convention::Rigify,
                "DEF-spine DEF-spine.001 DEF-spine.002 DEF-spine.006 DEF-thigh.L DEF-thigh.L.001 DEF-shin.L DEF-foot.L DEF-thigh.R DEF-shin.R DEF-foot.R",
            ),
        ];
        for (convention, list) in rigs {
            let found = recognise(&names(list)).unwrap_or_else(|| panic!("{convention}"));
            assert_eq!(found.convention, convention);
        }
        let unreal = recognise(&names(rigs[3].1)).unwrap();
        assert_eq!(
            unreal.roles[0], None,
            "the mannequin's root is no body part"
        );
        assert_eq!(unreal.roles[7], Some(Role::UpperLeg(Side::Left)));
        assert_eq!(unreal.roles[11], Some(Role::UpperLeg(Side::Right)));
    }

    #[test]
    fn a_rig_without_a_body_is_not_recognised() {
        assert_eq!(recognise(&names("root tail_01 tail_02 ear_l ear_r")), None);
        assert_eq!(recognise(&names("Hips Spine Head")), None);
    }
}
