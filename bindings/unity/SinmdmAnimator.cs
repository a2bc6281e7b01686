// Plays endless motion from a sinmdm model on a character's bones, in Unity. The model (a
// .onnx file renamed .bytes, imported as a TextAsset) drives the Transforms under this
// GameObject whose names are the model's joint names. Frames are prepared a few denoising
// steps per Update (MotionStream.Prepare), so reading them never blocks a frame once the
// first block is ready.
using UnityEngine;

namespace Sinmdm
{
    public sealed class SinmdmAnimator : MonoBehaviour
    {
        [Tooltip("The model: a sinmdm .onnx file renamed .bytes")]
        public TextAsset model;
        [Tooltip("Seed of the motion; the same seed gives the same motion on every machine")]
        public long seed = 1;
        [Tooltip("Denoising steps spent per frame preparing motion ahead")]
        public int stepsPerFrame = 2;
        [Tooltip("Metres per unit of the model's clip (0.01 for centimetres)")]
        public float metresPerUnit = 0.01f;

        Model loaded;
        MotionStream stream;
        Transform[] bones;
        float clock;
        int played;

        void Start()
        {
            loaded = Model.FromBytes(model.bytes, 1);
            stream = new MotionStream(loaded, (ulong)seed);
            bones = new Transform[loaded.Joints];
            var all = GetComponentsInChildren<Transform>();
            for (int j = 0; j < bones.Length; j++)
            {
                string name = loaded.JointName(j);
                foreach (var t in all)
                    if (t.name == name) { bones[j] = t; break; }
                if (bones[j] == null) Debug.LogWarning("sinmdm: no bone named " + name);
            }
        }

        void Update()
        {
            clock += Time.deltaTime;
            int due = (int)(clock * loaded.Info.Fps) - played;
            int ready = stream.Prepare(stepsPerFrame, Mathf.Max(due, 1) + (int)loaded.Info.Fps);
            if (due <= 0 || ready < due) return;
            Poses poses = stream.Next(due);
            played += due;
            Apply(poses, poses.Frames - 1);
        }

        void Apply(Poses poses, int frame)
        {
            var rotation = new float[4];
            for (int j = 0; j < bones.Length; j++)
            {
                if (bones[j] == null) continue;
                System.Array.Copy(poses.Rotations, 4 * (frame * poses.Joints + j), rotation, 0, 4);
                Coordinates.ToUnityRotation(loaded.Info, rotation, 0);
                bones[j].localRotation = new Quaternion(rotation[0], rotation[1], rotation[2], rotation[3]);
            }
            if (bones[0] != null)
            {
                var root = new float[3];
                System.Array.Copy(poses.RootPositions, 3 * frame, root, 0, 3);
                Coordinates.ToUnityPosition(loaded.Info, root, 0, metresPerUnit);
                bones[0].localPosition = new Vector3(root[0], root[1], root[2]);
            }
        }

        void OnDestroy()
        {
            if (stream != null) stream.Dispose();
            if (loaded != null) loaded.Dispose();
        }
    }
}
