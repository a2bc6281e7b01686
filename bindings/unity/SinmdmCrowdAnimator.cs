// Plays endless motion from one sinmdm model on many characters at once, in Unity: one Crowd
// whose characters' blocks are made together, a budget of denoising steps per Update. Each
// character is a rig under `characters` whose bone names are the model's joint names; character
// i walks with seed `seed + i` and, on a heading-relative model, turns at `turns[i]` rad/s
// (positive turns left) at the clip's mean speed. A character's motion is the same as a
// MotionStream of its own with the same seed and commands.
using UnityEngine;

namespace Sinmdm
{
    public sealed class SinmdmCrowdAnimator : MonoBehaviour
    {
        [Tooltip("The model: a sinmdm .onnx file renamed .bytes")]
        public TextAsset model;
        [Tooltip("The characters' rigs (bones named as the model's joints)")]
        public GameObject[] characters = new GameObject[0];
        [Tooltip("Seed of the first character; character i takes seed + i")]
        public long seed = 1;
        [Tooltip("Turn rate per character in rad/s (heading-relative models); none: free")]
        public float[] turns = new float[0];
        [Tooltip("Denoising steps per character spent per frame preparing motion ahead")]
        public int stepsPerCharacter = 2;
        [Tooltip("Metres per unit of the model's clip (0.01 for centimetres)")]
        public float metresPerUnit = 0.01f;

        Model loaded;
        Crowd crowd;
        ulong[] ids;
        Transform[][] bones;
        float clock;
        int played, commanded;
        double forward;

        /// <summary>Model frames shown so far (every character shows the same frame).</summary>
        public int FramesPlayed => played;

        void Start()
        {
            loaded = Model.FromBytes(model.bytes, 1);
            crowd = new Crowd(loaded);
            ids = new ulong[characters.Length];
            bones = new Transform[characters.Length][];
            if (turns.Length > 0)
            {
                var limits = loaded.SteerLimits();
                forward = 0.5 * (limits.ForwardMin + limits.ForwardMax);
            }
            for (int i = 0; i < characters.Length; i++)
            {
                ids[i] = crowd.Join(new StreamSettings { Seed = (ulong)(seed + i), Feet = Feet.Planted });
                bones[i] = FindBones(characters[i]);
            }
        }

        Transform[] FindBones(GameObject rig)
        {
            var found = new Transform[loaded.Joints];
            var all = rig.GetComponentsInChildren<Transform>();
            for (int j = 0; j < found.Length; j++)
            {
                string name = loaded.JointName(j);
                foreach (var t in all)
                    if (t.name == name) { found[j] = t; break; }
                if (found[j] == null) Debug.LogWarning("sinmdm: " + rig.name + " has no bone named " + name);
            }
            return found;
        }

        void Update()
        {
            clock += Time.deltaTime;
            int fps = (int)loaded.Info.Fps;
            int due = (int)(clock * loaded.Info.Fps) - played;
            Steer(played + 4 * (int)loaded.Info.ClipFrames + 4 * fps);
            crowd.Prepare(stepsPerCharacter * characters.Length, Mathf.Max(due, 1) + fps);
            // A budget of 0 only counts the characters short of the frames due.
            if (due <= 0 || crowd.Prepare(0, due) > 0) return;
            for (int i = 0; i < characters.Length; i++)
            {
                Poses poses = crowd.Next(ids[i], due);
                Apply(bones[i], poses, poses.Frames - 1);
            }
            played += due;
        }

        /// <summary>Gives every steered character its turn for the frames up to `until`.</summary>
        void Steer(int until)
        {
            if (turns.Length == 0 || until <= commanded) return;
            for (int i = 0; i < characters.Length && i < turns.Length; i++)
            {
                var told = new SteerFrame[until - commanded];
                for (int k = 0; k < told.Length; k++) told[k] = SteerFrame.Velocity(forward, turns[i]);
                crowd.Steer(ids[i], told);
            }
            commanded = until;
        }

        void Apply(Transform[] rig, Poses poses, int frame)
        {
            var rotation = new float[4];
            for (int j = 0; j < rig.Length; j++)
            {
                if (rig[j] == null) continue;
                System.Array.Copy(poses.Rotations, 4 * (frame * poses.Joints + j), rotation, 0, 4);
                Coordinates.ToUnityRotation(loaded.Info, rotation, 0);
                rig[j].localRotation = new Quaternion(rotation[0], rotation[1], rotation[2], rotation[3]);
            }
            if (rig.Length > 0 && rig[0] != null)
            {
                var root = new float[3];
                System.Array.Copy(poses.RootPositions, 3 * frame, root, 0, 3);
                Coordinates.ToUnityPosition(loaded.Info, root, 0, metresPerUnit);
                rig[0].localPosition = new Vector3(root[0], root[1], root[2]);
            }
        }

        void OnDestroy()
        {
            if (crowd != null) crowd.Dispose();
            if (loaded != null) loaded.Dispose();
        }
    }
}
