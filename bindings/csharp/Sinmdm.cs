// sinmdm for C# (Unity, Godot .NET, any .NET or Mono program): P/Invoke over the C ABI
// (capi/include/sinmdm.h). Drop this file into a Unity project's Assets folder and the shared
// libraries (sinmdm_c and onnxruntime) into Assets/Plugins; see the README's Embedding section.
//
// Every handle is IDisposable; a failed call throws SinmdmException with the library's message.
// A model and its streams must be used by one thread at a time; different models may run on
// different threads at once. Poses are in the model file's frame (right-handed, its up axis,
// its units); Coordinates converts them to Unity's (left-handed, Y-up, metres).
using System;
using System.Runtime.InteropServices;
using System.Text;

namespace Sinmdm
{
    /// <summary>A failed call: the status code and the library's message.</summary>
    public class SinmdmException : Exception
    {
        public readonly int Status;
        public SinmdmException(int status, string message) : base(message) { Status = status; }
    }

    /// <summary>What is done to the feet of the poses handed out.</summary>
    public enum Feet : uint { Planted = 0, Raw = 1 }

    /// <summary>The update rule of each denoising step (DDIM takes an eta).</summary>
    public enum Method : uint { Ancestral = 0, Ddim = 1, DpmSolver2M = 2 }

    /// <summary>A model's facts (sinmdm_model_info).</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct ModelInfo
    {
        public UIntPtr Joints, Features, ContactJoints;
        public double Fps, SkeletonHeight, UpX, UpY, UpZ;
        public UIntPtr ClipFrames, ReceptiveField, DiffusionSteps;
    }

    /// <summary>Poses as flat arrays: root position (3 per frame), local rotations x,y,z,w
    /// (4 per joint and frame), local translations (3 per joint and frame).</summary>
    public sealed class Poses
    {
        public readonly int Frames, Joints;
        public readonly float[] RootPositions, Rotations, Translations;
        public Poses(int frames, int joints)
        {
            Frames = frames; Joints = joints;
            RootPositions = new float[3 * frames];
            Rotations = new float[4 * joints * frames];
            Translations = new float[3 * joints * frames];
        }
    }

    internal static class Native
    {
        const string Lib = "sinmdm_c";

        [StructLayout(LayoutKind.Sequential)]
        internal struct Sampling { public ulong Seed; public uint Count, Steps, Feet, Method; public double Eta; }

        [StructLayout(LayoutKind.Sequential)]
        internal struct PoseBuffers
        {
            public IntPtr Root; public UIntPtr RootCapacity;
            public IntPtr Rotations; public UIntPtr RotationsCapacity;
            public IntPtr Translations; public UIntPtr TranslationsCapacity;
        }

        [StructLayout(LayoutKind.Sequential)]
        internal struct PosesIn { public UIntPtr Frames; public IntPtr Root, Rotations, Translations; }

        [StructLayout(LayoutKind.Sequential)]
        internal struct Span { public UIntPtr Start, End; }

        [StructLayout(LayoutKind.Sequential)]
        internal struct StreamOptions
        {
            public ulong Seed; public uint Steps, BlockFrames, Feet;
            public IntPtr ComposeJoints; public UIntPtr ComposeJointCount; public int ComposeRoot;
            public uint Method; public double Eta;
        }

        [DllImport(Lib)] internal static extern IntPtr sinmdm_last_error();
        [DllImport(Lib)] internal static extern int sinmdm_load_onnxruntime(byte[] path);
        [DllImport(Lib)] internal static extern int sinmdm_model_open(byte[] path, uint threads, out IntPtr model);
        [DllImport(Lib)] internal static extern int sinmdm_model_open_bytes(byte[] bytes, UIntPtr length, uint threads, out IntPtr model);
        [DllImport(Lib)] internal static extern void sinmdm_model_free(IntPtr model);
        [DllImport(Lib)] internal static extern int sinmdm_model_info(IntPtr model, out ModelInfo info);
        [DllImport(Lib)] internal static extern int sinmdm_model_joint_name(IntPtr model, UIntPtr joint, byte[] buffer, UIntPtr capacity, out UIntPtr needed);
        [DllImport(Lib)] internal static extern int sinmdm_model_find_joint(IntPtr model, byte[] name, out UIntPtr index);
        [DllImport(Lib)] internal static extern int sinmdm_generate(IntPtr model, ref Sampling sampling, UIntPtr frames, out IntPtr result);
        [DllImport(Lib)] internal static extern int sinmdm_inbetween(IntPtr model, ref Sampling sampling, ref PosesIn reference, Span[] keep, UIntPtr spanCount, UIntPtr ramp, out IntPtr result);
        [DllImport(Lib)] internal static extern int sinmdm_expand(IntPtr model, ref Sampling sampling, ref PosesIn reference, UIntPtr prefix, UIntPtr suffix, UIntPtr ramp, out IntPtr result);
        [DllImport(Lib)] internal static extern int sinmdm_compose(IntPtr model, ref Sampling sampling, ref PosesIn reference, UIntPtr[] joints, UIntPtr jointCount, int root, Span[] spans, UIntPtr spanCount, UIntPtr ramp, out IntPtr result);
        [DllImport(Lib)] internal static extern int sinmdm_harmonize(IntPtr model, ref Sampling sampling, ref PosesIn content, UIntPtr factor, double freeShare, out IntPtr result);
        [DllImport(Lib)] internal static extern int sinmdm_stream_supply(IntPtr stream, IntPtr model, ref PosesIn poses);
        [DllImport(Lib)] internal static extern int sinmdm_result_count(IntPtr result, out UIntPtr count);
        [DllImport(Lib)] internal static extern int sinmdm_result_frames(IntPtr result, out UIntPtr frames);
        [DllImport(Lib)] internal static extern int sinmdm_result_poses(IntPtr result, UIntPtr sample, ref PoseBuffers buffers);
        [DllImport(Lib)] internal static extern void sinmdm_result_free(IntPtr result);
        [DllImport(Lib)] internal static extern int sinmdm_stream_new(IntPtr model, ref StreamOptions options, out IntPtr stream);
        [DllImport(Lib)] internal static extern int sinmdm_stream_next(IntPtr stream, IntPtr model, UIntPtr frames, ref PoseBuffers buffers);
        [DllImport(Lib)] internal static extern void sinmdm_stream_free(IntPtr stream);
        [DllImport(Lib)] internal static extern int sinmdm_write_bvh(IntPtr model, ref PosesIn poses, byte[] path);

        internal static byte[] Utf8(string text) => Encoding.UTF8.GetBytes(text + "\0");

        internal static void Check(int status)
        {
            if (status == 0) return;
            IntPtr message = sinmdm_last_error();
            int length = 0;
            while (Marshal.ReadByte(message, length) != 0) length++;
            var bytes = new byte[length];
            Marshal.Copy(message, bytes, 0, length);
            throw new SinmdmException(status, Encoding.UTF8.GetString(bytes));
        }

        /// Pins the arrays of `poses` for the duration of `use`.
        internal static T WithBuffers<T>(Poses poses, Func<PoseBuffers, T> use)
        {
            var root = GCHandle.Alloc(poses.RootPositions, GCHandleType.Pinned);
            var rot = GCHandle.Alloc(poses.Rotations, GCHandleType.Pinned);
            var trans = GCHandle.Alloc(poses.Translations, GCHandleType.Pinned);
            try
            {
                return use(new PoseBuffers
                {
                    Root = root.AddrOfPinnedObject(), RootCapacity = (UIntPtr)poses.RootPositions.Length,
                    Rotations = rot.AddrOfPinnedObject(), RotationsCapacity = (UIntPtr)poses.Rotations.Length,
                    Translations = trans.AddrOfPinnedObject(), TranslationsCapacity = (UIntPtr)poses.Translations.Length,
                });
            }
            finally { root.Free(); rot.Free(); trans.Free(); }
        }

        internal static T WithInput<T>(Poses poses, Func<PosesIn, T> use) =>
            WithBuffers(poses, b => use(new PosesIn
            {
                Frames = (UIntPtr)poses.Frames, Root = b.Root, Rotations = b.Rotations, Translations = b.Translations,
            }));
    }

    /// <summary>The onnxruntime shared library to use (call before opening a model, or let the
    /// library find it through ORT_DYLIB_PATH).</summary>
    public static class Runtime
    {
        /// <summary>Respaced sampling steps used unless told otherwise (SINMDM_DEFAULT_STEPS).</summary>
        public const uint DefaultSteps = 50;

        /// <summary>A `steps` value that runs all of the model's diffusion steps T (SINMDM_ALL_STEPS;
        /// slow, the reference quality). 0 gives DefaultSteps.</summary>
        public const uint AllSteps = 4294967295;

        public static void Load(string path) => Native.Check(Native.sinmdm_load_onnxruntime(path == null ? null : Native.Utf8(path)));
    }

    /// <summary>An open model.</summary>
    public sealed class Model : IDisposable
    {
        internal IntPtr Handle;
        public readonly ModelInfo Info;
        public int Joints => (int)Info.Joints;

        Model(IntPtr handle)
        {
            Handle = handle;
            Native.Check(Native.sinmdm_model_info(handle, out Info));
        }

        /// <summary>Opens a model file; threads 0 uses every core.</summary>
        public static Model Open(string path, uint threads = 0)
        {
            Native.Check(Native.sinmdm_model_open(Native.Utf8(path), threads, out IntPtr handle));
            return new Model(handle);
        }

        /// <summary>Opens a model from bytes (a Unity TextAsset's bytes, say).</summary>
        public static Model FromBytes(byte[] bytes, uint threads = 0)
        {
            Native.Check(Native.sinmdm_model_open_bytes(bytes, (UIntPtr)bytes.Length, threads, out IntPtr handle));
            return new Model(handle);
        }

        public string JointName(int joint)
        {
            Native.sinmdm_model_joint_name(Handle, (UIntPtr)joint, null, UIntPtr.Zero, out UIntPtr needed);
            var buffer = new byte[(int)needed];
            Native.Check(Native.sinmdm_model_joint_name(Handle, (UIntPtr)joint, buffer, needed, out needed));
            return Encoding.UTF8.GetString(buffer, 0, buffer.Length - 1);
        }

        public int FindJoint(string name)
        {
            Native.Check(Native.sinmdm_model_find_joint(Handle, Native.Utf8(name), out UIntPtr index));
            return (int)index;
        }

        /// <summary>New motion: `count` samples of `frames` frames.</summary>
        public Result Generate(int frames, ulong seed, int count = 1, uint steps = Runtime.DefaultSteps, Feet feet = Feet.Planted,
                               Method method = Method.Ancestral, double eta = 0.0)
        {
            var sampling = new Native.Sampling { Seed = seed, Count = (uint)count, Steps = steps, Feet = (uint)feet,
                                                 Method = (uint)method, Eta = eta };
            Native.Check(Native.sinmdm_generate(Handle, ref sampling, (UIntPtr)frames, out IntPtr result));
            return new Result(result, Joints);
        }

        /// <summary>In-betweening: keep the spans of the reference given as start, end pairs
        /// (end excluded), fill the gaps.</summary>
        public Result Inbetween(Poses reference, int[] keep, int ramp, ulong seed, uint steps = Runtime.DefaultSteps, Feet feet = Feet.Planted)
        {
            var sampling = new Native.Sampling { Seed = seed, Count = 1, Steps = steps, Feet = (uint)feet };
            var spans = new Native.Span[keep.Length / 2];
            for (int i = 0; i < spans.Length; i++)
                spans[i] = new Native.Span { Start = (UIntPtr)keep[2 * i], End = (UIntPtr)keep[2 * i + 1] };
            IntPtr result = IntPtr.Zero;
            Native.WithInput(reference, input =>
            {
                Native.Check(Native.sinmdm_inbetween(Handle, ref sampling, ref input, spans, (UIntPtr)spans.Length, (UIntPtr)ramp, out result));
                return 0;
            });
            return new Result(result, Joints);
        }

        /// <summary>Expansion: new frames before and after the reference.</summary>
        public Result Expand(Poses reference, int prefix, int suffix, int ramp, ulong seed, uint steps = Runtime.DefaultSteps, Feet feet = Feet.Planted)
        {
            var sampling = new Native.Sampling { Seed = seed, Count = 1, Steps = steps, Feet = (uint)feet };
            IntPtr result = IntPtr.Zero;
            Native.WithInput(reference, input =>
            {
                Native.Check(Native.sinmdm_expand(Handle, ref sampling, ref input, (UIntPtr)prefix, (UIntPtr)suffix, (UIntPtr)ramp, out result));
                return 0;
            });
            return new Result(result, Joints);
        }

        /// <summary>Composition: the joints (and the root's travel when root) from the reference on
        /// every frame, the rest of the body generated.</summary>
        public Result Compose(Poses reference, int[] joints, bool root, int ramp, ulong seed, uint steps = Runtime.DefaultSteps, Feet feet = Feet.Planted)
        {
            var sampling = new Native.Sampling { Seed = seed, Count = 1, Steps = steps, Feet = (uint)feet };
            var indices = Array.ConvertAll(joints, j => (UIntPtr)j);
            IntPtr result = IntPtr.Zero;
            Native.WithInput(reference, input =>
            {
                Native.Check(Native.sinmdm_compose(Handle, ref sampling, ref input, indices, (UIntPtr)indices.Length, root ? 1 : 0,
                                                   null, UIntPtr.Zero, (UIntPtr)ramp, out result));
                return 0;
            });
            return new Result(result, Joints);
        }

        /// <summary>Harmonization (style transfer): the content's low frequencies in the model's style.</summary>
        public Result Harmonize(Poses content, int factor, double freeShare, ulong seed, uint steps = Runtime.DefaultSteps, Feet feet = Feet.Planted)
        {
            var sampling = new Native.Sampling { Seed = seed, Count = 1, Steps = steps, Feet = (uint)feet };
            IntPtr result = IntPtr.Zero;
            Native.WithInput(content, input =>
            {
                Native.Check(Native.sinmdm_harmonize(Handle, ref sampling, ref input, (UIntPtr)factor, freeShare, out result));
                return 0;
            });
            return new Result(result, Joints);
        }

        /// <summary>Writes poses of this model's skeleton as a BVH file.</summary>
        public void WriteBvh(Poses poses, string path) =>
            Native.WithInput(poses, input => { Native.Check(Native.sinmdm_write_bvh(Handle, ref input, Native.Utf8(path))); return 0; });

        public void Dispose()
        {
            Native.sinmdm_model_free(Handle);
            Handle = IntPtr.Zero;
        }
    }

    /// <summary>A generated batch.</summary>
    public sealed class Result : IDisposable
    {
        IntPtr handle;
        readonly int joints;
        public readonly int Count, Frames;

        internal Result(IntPtr handle, int joints)
        {
            this.handle = handle;
            this.joints = joints;
            Native.Check(Native.sinmdm_result_count(handle, out UIntPtr count));
            Native.Check(Native.sinmdm_result_frames(handle, out UIntPtr frames));
            Count = (int)count;
            Frames = (int)frames;
        }

        public Poses Poses(int sample)
        {
            var poses = new Poses(Frames, joints);
            Native.WithBuffers(poses, b => { Native.Check(Native.sinmdm_result_poses(handle, (UIntPtr)sample, ref b)); return 0; });
            return poses;
        }

        public void Dispose()
        {
            Native.sinmdm_result_free(handle);
            handle = IntPtr.Zero;
        }
    }

    /// <summary>Endless motion, a chunk at a time (the same whatever chunk sizes are asked).</summary>
    public sealed class Stream : IDisposable
    {
        IntPtr handle;
        readonly Model model;

        public Stream(Model model, ulong seed, uint steps = Runtime.DefaultSteps, uint blockFrames = 0, Feet feet = Feet.Planted,
                      Method method = Method.Ancestral)
        {
            this.model = model;
            var options = new Native.StreamOptions { Seed = seed, Steps = steps, BlockFrames = blockFrames, Feet = (uint)feet,
                                                     Method = (uint)method };
            Native.Check(Native.sinmdm_stream_new(model.Handle, ref options, out handle));
        }

        /// <summary>Poses for the frames after the last supplied ones, for a composed stream.</summary>
        public void Supply(Poses poses) =>
            Native.WithInput(poses, input => { Native.Check(Native.sinmdm_stream_supply(handle, model.Handle, ref input)); return 0; });

        public Poses Next(int frames)
        {
            var poses = new Poses(frames, model.Joints);
            Native.WithBuffers(poses, b => { Native.Check(Native.sinmdm_stream_next(handle, model.Handle, (UIntPtr)frames, ref b)); return 0; });
            return poses;
        }

        public void Dispose()
        {
            Native.sinmdm_stream_free(handle);
            handle = IntPtr.Zero;
        }
    }

    /// <summary>From the model file's frame (right-handed, its up axis, its units) to Unity's
    /// (left-handed, Y-up, metres).</summary>
    public static class Coordinates
    {
        /// <summary>A position: turned so the file's up is +Y, X mirrored, scaled to metres
        /// (`metresPerUnit`: 0.01 for a file in centimetres).</summary>
        public static void ToUnityPosition(ModelInfo info, float[] xyz, int offset, float metresPerUnit)
        {
            float x = xyz[offset], y = xyz[offset + 1], z = xyz[offset + 2];
            if (info.UpZ > 0.5) { float t = y; y = z; z = -t; }  // Z-up: (x, y, z) -> (x, z, -y)
            xyz[offset] = -x * metresPerUnit;
            xyz[offset + 1] = y * metresPerUnit;
            xyz[offset + 2] = z * metresPerUnit;
        }

        /// <summary>A rotation x,y,z,w, turned the same way, then mirrored in X.</summary>
        public static void ToUnityRotation(ModelInfo info, float[] xyzw, int offset)
        {
            float x = xyzw[offset], y = xyzw[offset + 1], z = xyzw[offset + 2];
            if (info.UpZ > 0.5) { float t = y; y = z; z = -t; }
            xyzw[offset] = x;
            xyzw[offset + 1] = -y;
            xyzw[offset + 2] = -z;
        }
    }
}
