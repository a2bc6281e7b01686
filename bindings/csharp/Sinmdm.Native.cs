// The native side of the C# binding (see Sinmdm.cs): the C ABI's declarations, its structs as
// laid out in capi/include/sinmdm.h, the SafeHandles that free what was never disposed, and the
// helpers that pin arrays and turn statuses into exceptions.
using System;
using System.Runtime.InteropServices;
using System.Text;

#if !UNITY_5_3_OR_NEWER
namespace AOT
{
    /// <summary>Marks a static method called from native code (Unity defines this attribute;
    /// IL2CPP needs it to make the method callable from C).</summary>
    [AttributeUsage(AttributeTargets.Method)]
    public sealed class MonoPInvokeCallbackAttribute : Attribute
    {
        public MonoPInvokeCallbackAttribute(Type type) { }
    }
}
#endif

namespace Sinmdm
{
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
        internal struct Dance
        {
            public IntPtr ReferenceBeats; public UIntPtr ReferenceBeatCount;
            public IntPtr MusicBeats; public UIntPtr MusicBeatCount;
            public UIntPtr Frames, Hold, Ramp;
            public uint Order, Level, KeepRoot;
        }

        [StructLayout(LayoutKind.Sequential)]
        internal struct SteerLimits { public double ForwardMin, ForwardMax, TurnMax; }

        [StructLayout(LayoutKind.Sequential)]
        internal struct SteerSideways { public double LeftwardMin, LeftwardMax; }

        [StructLayout(LayoutKind.Sequential)]
        internal struct StreamOptions
        {
            public ulong Seed; public uint Steps, BlockFrames, Feet;
            public IntPtr ComposeJoints; public UIntPtr ComposeJointCount; public int ComposeRoot;
            public uint Method; public double Eta;
        }

        [UnmanagedFunctionPointer(CallingConvention.Cdecl)]
        internal delegate int ProgressFn(IntPtr userdata, UIntPtr done, UIntPtr total);

        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern IntPtr sinmdm_last_error();
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern UIntPtr sinmdm_live_handles();
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_load_onnxruntime(byte[] path);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_model_open(byte[] path, uint threads, out ModelHandle model);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_model_open_bytes(byte[] bytes, UIntPtr length, uint threads, out ModelHandle model);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern void sinmdm_model_free(IntPtr model);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_model_info(ModelHandle model, out ModelInfo info);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_model_set_progress(ModelHandle model, ProgressFn callback, IntPtr userdata);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_model_joint_name(ModelHandle model, UIntPtr joint, byte[] buffer, UIntPtr capacity, out UIntPtr needed);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_model_find_joint(ModelHandle model, byte[] name, out UIntPtr index);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_model_parents(ModelHandle model, int[] parents, UIntPtr capacity, out UIntPtr needed);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_model_rest_offsets(ModelHandle model, float[] offsets, UIntPtr capacity, out UIntPtr needed);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_model_contact_joints(ModelHandle model, UIntPtr[] joints, UIntPtr capacity, out UIntPtr needed);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_generate(ModelHandle model, ref Sampling sampling, UIntPtr frames, out ResultHandle result);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_generate_begin(ModelHandle model, ref Sampling sampling, UIntPtr frames, out RunHandle run);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_dance(ModelHandle model, ref Sampling sampling, ref PosesIn reference, ref Dance dance, out ResultHandle result);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_dance_begin(ModelHandle model, ref Sampling sampling, ref PosesIn reference, ref Dance dance, out RunHandle run);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_dance_reference_beats(ModelHandle model, ref PosesIn reference, UIntPtr[] beats, UIntPtr capacity, out UIntPtr needed);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_steer_commands(ModelHandle model, ref Sampling sampling, UIntPtr frames, SteerFrame[] commands, UIntPtr commandCount, UIntPtr ramp, out ResultHandle result);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_steer_commands_begin(ModelHandle model, ref Sampling sampling, UIntPtr frames, SteerFrame[] commands, UIntPtr commandCount, UIntPtr ramp, out RunHandle run);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_steer_limits(ModelHandle model, out SteerLimits limits);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_steer_sideways_limits(ModelHandle model, out SteerSideways sideways);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_stream_steer_commands(StreamHandle stream, SteerFrame[] commands, UIntPtr count);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_inbetween(ModelHandle model, ref Sampling sampling, ref PosesIn reference, Span[] keep, UIntPtr spanCount, UIntPtr ramp, out ResultHandle result);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_inbetween_begin(ModelHandle model, ref Sampling sampling, ref PosesIn reference, Span[] keep, UIntPtr spanCount, UIntPtr ramp, out RunHandle run);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_expand(ModelHandle model, ref Sampling sampling, ref PosesIn reference, UIntPtr prefix, UIntPtr suffix, UIntPtr ramp, out ResultHandle result);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_expand_begin(ModelHandle model, ref Sampling sampling, ref PosesIn reference, UIntPtr prefix, UIntPtr suffix, UIntPtr ramp, out RunHandle run);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_compose(ModelHandle model, ref Sampling sampling, ref PosesIn reference, UIntPtr[] joints, UIntPtr jointCount, int root, Span[] spans, UIntPtr spanCount, UIntPtr ramp, out ResultHandle result);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_compose_begin(ModelHandle model, ref Sampling sampling, ref PosesIn reference, UIntPtr[] joints, UIntPtr jointCount, int root, Span[] spans, UIntPtr spanCount, UIntPtr ramp, out RunHandle run);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_harmonize(ModelHandle model, ref Sampling sampling, ref PosesIn content, UIntPtr factor, double freeShare, out ResultHandle result);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_harmonize_begin(ModelHandle model, ref Sampling sampling, ref PosesIn content, UIntPtr factor, double freeShare, out RunHandle run);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_run_step(RunHandle run, ModelHandle model, UIntPtr maxSteps, out UIntPtr done, out UIntPtr total);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_run_finish(RunHandle run, out ResultHandle result);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern void sinmdm_run_free(IntPtr run);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_result_count(ResultHandle result, out UIntPtr count);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_result_frames(ResultHandle result, out UIntPtr frames);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_result_poses(ResultHandle result, UIntPtr sample, ref PoseBuffers buffers);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern void sinmdm_result_free(IntPtr result);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_stream_new(ModelHandle model, ref StreamOptions options, out StreamHandle stream);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_stream_supply(StreamHandle stream, ModelHandle model, ref PosesIn poses);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_stream_next(StreamHandle stream, ModelHandle model, UIntPtr frames, ref PoseBuffers buffers);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_stream_step(StreamHandle stream, ModelHandle model, UIntPtr maxSteps, UIntPtr ahead, out UIntPtr ready, out UIntPtr done, out UIntPtr total);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern void sinmdm_stream_free(IntPtr stream);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_crowd_new(ModelHandle model, out CrowdHandle crowd);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_crowd_join(CrowdHandle crowd, ref StreamOptions options, out ulong id);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_crowd_leave(CrowdHandle crowd, ulong id);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_crowd_count(CrowdHandle crowd, out UIntPtr count);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_crowd_steer(CrowdHandle crowd, ulong id, SteerFrame[] commands, UIntPtr count);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_crowd_supply(CrowdHandle crowd, ModelHandle model, ulong id, ref PosesIn poses);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_crowd_step(CrowdHandle crowd, ModelHandle model, UIntPtr maxSteps, UIntPtr ahead, out UIntPtr steps, out UIntPtr waiting);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_crowd_next(CrowdHandle crowd, ModelHandle model, ulong id, UIntPtr frames, ref PoseBuffers buffers);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern void sinmdm_crowd_free(IntPtr crowd);
        [DllImport(Lib, CallingConvention = CallingConvention.Cdecl)] internal static extern int sinmdm_write_bvh(ModelHandle model, ref PosesIn poses, byte[] path);

        internal static byte[] Utf8(string text)
        {
            if (text == null) throw new ArgumentNullException(nameof(text));
            return Encoding.UTF8.GetBytes(text + "\0");
        }

        internal static string LastError()
        {
            IntPtr message = sinmdm_last_error();
            int length = 0;
            while (Marshal.ReadByte(message, length) != 0) length++;
            var bytes = new byte[length];
            Marshal.Copy(message, bytes, 0, length);
            return Encoding.UTF8.GetString(bytes);
        }

        internal static void Check(int status)
        {
            if (status == 0) return;
            throw new SinmdmException((Status)status, LastError());
        }

        internal static UIntPtr Size(int value, string name)
        {
            if (value < 0) throw new ArgumentOutOfRangeException(name, value, "must not be negative");
            return (UIntPtr)(ulong)value;
        }

        /// Pins the arrays of `poses` for the duration of `use`.
        internal static T WithBuffers<T>(Poses poses, Func<PoseBuffers, T> use)
        {
            if (poses == null) throw new ArgumentNullException(nameof(poses));
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

        /// Poses handed to the library for a skeleton of `joints` joints: the library reads as many
        /// values as the model's skeleton needs, so poses of another skeleton are refused here.
        internal static T WithInput<T>(Poses poses, int joints, Func<PosesIn, T> use)
        {
            if (poses == null) throw new ArgumentNullException(nameof(poses));
            if (poses.Joints != joints)
                throw new ArgumentException("the poses have " + poses.Joints + " joints, the model's skeleton " + joints, nameof(poses));
            return WithBuffers(poses, b => use(new PosesIn
            {
                Frames = (UIntPtr)poses.Frames, Root = b.Root, Rotations = b.Rotations, Translations = b.Translations,
            }));
        }

        /// Start, end pairs as spans; an odd count or a negative frame is refused.
        internal static Span[] Spans(int[] pairs, string name)
        {
            if (pairs == null) return new Span[0];
            if (pairs.Length % 2 != 0)
                throw new ArgumentException("spans are start, end pairs: an even count of numbers, got " + pairs.Length, name);
            var spans = new Span[pairs.Length / 2];
            for (int i = 0; i < spans.Length; i++)
                spans[i] = new Span { Start = Size(pairs[2 * i], name), End = Size(pairs[2 * i + 1], name) };
            return spans;
        }

        /// Pins a dance's beat arrays for the duration of `use`; negative frames are refused.
        internal static T WithDance<T>(DanceSettings dance, Func<Dance, T> use)
        {
            if (dance == null) throw new ArgumentNullException(nameof(dance));
            var reference = Indices(dance.ReferenceBeats, nameof(dance.ReferenceBeats));
            var music = Indices(dance.MusicBeats, nameof(dance.MusicBeats));
            var r = GCHandle.Alloc(reference, GCHandleType.Pinned);
            var m = GCHandle.Alloc(music, GCHandleType.Pinned);
            try
            {
                return use(new Dance
                {
                    ReferenceBeats = r.AddrOfPinnedObject(), ReferenceBeatCount = (UIntPtr)reference.Length,
                    MusicBeats = m.AddrOfPinnedObject(), MusicBeatCount = (UIntPtr)music.Length,
                    Frames = Size(dance.Frames, nameof(dance.Frames)), Hold = Size(dance.Hold, nameof(dance.Hold)),
                    Ramp = Size(dance.Ramp, nameof(dance.Ramp)),
                    Order = (uint)dance.Order, Level = (uint)dance.Level, KeepRoot = dance.KeepRoot ? 1u : 0u,
                });
            }
            finally { r.Free(); m.Free(); }
        }

        internal static UIntPtr[] Indices(int[] joints, string name)
        {
            if (joints == null) return new UIntPtr[0];
            return Array.ConvertAll(joints, j => Size(j, name));
        }
    }

    /// <summary>The native handle of a model; freed by Dispose or, if forgotten, by the finalizer.</summary>
    public sealed class ModelHandle : SafeHandle
    {
        public ModelHandle() : base(IntPtr.Zero, true) { }
        public override bool IsInvalid => handle == IntPtr.Zero;
        protected override bool ReleaseHandle() { Native.sinmdm_model_free(handle); return true; }
    }

    /// <summary>The native handle of a run.</summary>
    public sealed class RunHandle : SafeHandle
    {
        public RunHandle() : base(IntPtr.Zero, true) { }
        public override bool IsInvalid => handle == IntPtr.Zero;
        protected override bool ReleaseHandle() { Native.sinmdm_run_free(handle); return true; }
    }

    /// <summary>The native handle of a batch.</summary>
    public sealed class ResultHandle : SafeHandle
    {
        public ResultHandle() : base(IntPtr.Zero, true) { }
        public override bool IsInvalid => handle == IntPtr.Zero;
        protected override bool ReleaseHandle() { Native.sinmdm_result_free(handle); return true; }
    }

    /// <summary>The native handle of a stream.</summary>
    public sealed class StreamHandle : SafeHandle
    {
        public StreamHandle() : base(IntPtr.Zero, true) { }
        public override bool IsInvalid => handle == IntPtr.Zero;
        protected override bool ReleaseHandle() { Native.sinmdm_stream_free(handle); return true; }
    }

    /// <summary>The native handle of a crowd.</summary>
    public sealed class CrowdHandle : SafeHandle
    {
        public CrowdHandle() : base(IntPtr.Zero, true) { }
        public override bool IsInvalid => handle == IntPtr.Zero;
        protected override bool ReleaseHandle() { Native.sinmdm_crowd_free(handle); return true; }
    }
}
