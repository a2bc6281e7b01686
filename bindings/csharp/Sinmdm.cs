// sinmdm for C# (Unity, Godot .NET, any .NET or Mono program): P/Invoke over the C ABI
// (capi/include/sinmdm.h). In Unity, install the package that scripts/unity_package.sh builds
// (this file, the native libraries and an assembly definition); elsewhere compile this file
// with your program and put sinmdm_c and onnxruntime where the loader finds them.
//
// Every handle is a SafeHandle: Dispose frees it, and a finalizer frees one that was never
// disposed. A failed call throws SinmdmException with the library's status and message
// (SinmdmCancelledException when a progress callback stopped it). A model and the runs and
// streams made on it must be used by one thread at a time; different models may run on
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
        public readonly Status Status;
        public SinmdmException(Status status, string message, Exception inner = null) : base(message, inner) { Status = status; }
    }

    /// <summary>A progress callback stopped the call (it returned false or threw; a thrown
    /// exception is the InnerException).</summary>
    public sealed class SinmdmCancelledException : SinmdmException
    {
        public SinmdmCancelledException(string message, Exception inner) : base(Status.Cancelled, message, inner) { }
    }

    /// <summary>What a call did (SinmdmStatus).</summary>
    public enum Status
    {
        Ok = 0, NullArgument = 1, InvalidArgument = 2, BufferTooSmall = 3, UnknownJoint = 4,
        RuntimeLibrary = 5, BadModel = 6, TaskFailed = 7, Io = 8, Internal = 9, Cancelled = 10,
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

    /// <summary>How a task samples: the seed, the crowd size, the steps, the feet and the
    /// update rule. The same model, sampling and arguments give the same poses everywhere.</summary>
    public struct Sampling
    {
        public ulong Seed;
        public int Count;
        public uint Steps;
        public Feet Feet;
        public Method Method;
        public double Eta;

        /// <summary>One sample with the default steps, planted feet, ancestral sampling.</summary>
        public static Sampling Default(ulong seed) =>
            new Sampling { Seed = seed, Count = 1, Steps = Runtime.DefaultSteps, Feet = Feet.Planted, Method = Method.Ancestral };

        internal Native.Sampling ToNative()
        {
            if (Count < 1) throw new ArgumentOutOfRangeException(nameof(Count), Count, "a batch has at least one sample");
            return new Native.Sampling { Seed = Seed, Count = (uint)Count, Steps = Steps, Feet = (uint)Feet, Method = (uint)Method, Eta = Eta };
        }
    }

    /// <summary>What a steering frame asks for.</summary>
    public enum SteerKind : uint { Free = 0, Velocity = 1, Position = 2, Facing = 3, PositionFacing = 4 }

    /// <summary>One frame's steering command for a heading-relative model (file frame: the
    /// model's up axis and units); the layout of the C ABI's SinmdmSteerCommand.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct SteerFrame
    {
        public SteerKind Kind;
        /// <summary>0 (keeps the numbers 8-byte aligned; the C struct is 72 bytes).</summary>
        public uint Reserved;
        /// <summary>Velocity: forward speed, file units per second.</summary>
        public double Forward;
        /// <summary>Velocity: turn rate, radians per second; positive turns left.</summary>
        public double Turn;
        /// <summary>Position and PositionFacing: the root's ground position (the up component
        /// is ignored).</summary>
        public double X, Y, Z;
        /// <summary>Facing and PositionFacing: the direction the character faces (the up
        /// component is ignored; the rest must not be zero).</summary>
        public double FacingX, FacingY, FacingZ;

        public static SteerFrame Velocity(double forward, double turn) =>
            new SteerFrame { Kind = SteerKind.Velocity, Forward = forward, Turn = turn };

        public static SteerFrame Position(double x, double y, double z) =>
            new SteerFrame { Kind = SteerKind.Position, X = x, Y = y, Z = z };

        public static SteerFrame Facing(double x, double y, double z) =>
            new SteerFrame { Kind = SteerKind.Facing, FacingX = x, FacingY = y, FacingZ = z };

        public static SteerFrame PositionFacing(double x, double y, double z, double facingX, double facingY, double facingZ) =>
            new SteerFrame { Kind = SteerKind.PositionFacing, X = x, Y = y, Z = z, FacingX = facingX, FacingY = facingY, FacingZ = facingZ };
    }

    /// <summary>The range of steering commands a model's clip supports.</summary>
    public struct SteerLimits
    {
        public double ForwardMin, ForwardMax, TurnMax;
        /// <summary>Fastest rightward (negative) and leftward speeds, file units per second.</summary>
        public double SidewaysMin, SidewaysMax;
    }

    /// <summary>The order of a dance's keyframes.</summary>
    public enum DanceOrder : uint { Shuffled = 0, Reference = 1 }

    /// <summary>Which of the music's beats carry a dance's keyframes.</summary>
    public enum BeatLevel : uint { Auto = 0, Every = 1, EveryOther = 2, Half = 3 }

    /// <summary>A dance's beats (frames at the model's rate, increasing) and placement.</summary>
    public sealed class DanceSettings
    {
        /// <summary>The reference's beats (Model.DanceReferenceBeats gives them).</summary>
        public int[] ReferenceBeats;
        /// <summary>The music's beats, frames of the output.</summary>
        public int[] MusicBeats;
        /// <summary>Frames of the output.</summary>
        public int Frames;
        /// <summary>Half-width of each keyframe window in frames; 0 for the library's default.</summary>
        public int Hold;
        /// <summary>Soft border on the kept side of each window, in frames.</summary>
        public int Ramp = 13;
        public DanceOrder Order = DanceOrder.Shuffled;
        public BeatLevel Level = BeatLevel.Auto;
        /// <summary>Whether the root's travel and height in each window come from the reference.</summary>
        public bool KeepRoot = true;
    }

    /// <summary>Poses as flat arrays: root position (3 per frame), local rotations x,y,z,w
    /// (4 per joint and frame), local translations (3 per joint and frame).</summary>
    public sealed class Poses
    {
        public readonly int Frames, Joints;
        public readonly float[] RootPositions, Rotations, Translations;
        public Poses(int frames, int joints)
        {
            if (frames < 0) throw new ArgumentOutOfRangeException(nameof(frames));
            if (joints < 1) throw new ArgumentOutOfRangeException(nameof(joints));
            Frames = frames; Joints = joints;
            RootPositions = new float[3 * frames];
            Rotations = new float[4 * joints * frames];
            Translations = new float[3 * joints * frames];
        }
    }

    /// <summary>The onnxruntime shared library and the library's own bookkeeping.</summary>
    public static class Runtime
    {
        /// <summary>Respaced sampling steps used unless told otherwise (SINMDM_DEFAULT_STEPS).</summary>
        public const uint DefaultSteps = 50;
        /// <summary>Respaced steps per block of a stream unless told otherwise (SINMDM_DEFAULT_STREAM_STEPS).</summary>
        public const uint DefaultStreamSteps = 20;

        /// <summary>A `steps` value that runs all of the model's diffusion steps T (SINMDM_ALL_STEPS;
        /// slow, the reference quality). 0 gives DefaultSteps.</summary>
        public const uint AllSteps = 4294967295;

        /// <summary>Loads onnxruntime from `path`, or (null) searches for it: ORT_DYLIB_PATH, next
        /// to the executable, next to sinmdm_c, the system's library path.</summary>
        public static void Load(string path) => Native.Check(Native.sinmdm_load_onnxruntime(path == null ? null : Native.Utf8(path)));

        /// <summary>Native handles alive (models, runs, results, streams): for leak checks.</summary>
        public static long LiveHandles => (long)(ulong)Native.sinmdm_live_handles();
    }

    /// <summary>An open model.</summary>
    public sealed class Model : IDisposable
    {
        internal readonly ModelHandle Handle;
        public readonly ModelInfo Info;
        public int Joints => (int)Info.Joints;

        // The progress callback: a static thunk (IL2CPP can call only static methods marked
        // MonoPInvokeCallback) that finds the model's managed callback through a GCHandle.
        static readonly Native.ProgressFn Thunk = ProgressThunk;
        Func<int, int, bool> progress;
        Exception progressError;
        GCHandle self;

        Model(ModelHandle handle)
        {
            Handle = handle;
            Native.Check(Native.sinmdm_model_info(handle, out Info));
        }

        /// <summary>Opens a model file; `threads` is how many samples of a batch run at once (0:
        /// every core); it changes speed, never values.</summary>
        public static Model Open(string path, uint threads = 0)
        {
            int status = Native.sinmdm_model_open(Native.Utf8(path), threads, out ModelHandle handle);
            if (status != 0) { handle.Dispose(); Native.Check(status); }
            return new Model(handle);
        }

        /// <summary>Opens a model from bytes (a Unity TextAsset's bytes, say); they are copied.</summary>
        public static Model FromBytes(byte[] bytes, uint threads = 0)
        {
            if (bytes == null) throw new ArgumentNullException(nameof(bytes));
            int status = Native.sinmdm_model_open_bytes(bytes, (UIntPtr)bytes.Length, threads, out ModelHandle handle);
            if (status != 0) { handle.Dispose(); Native.Check(status); }
            return new Model(handle);
        }

        [AOT.MonoPInvokeCallback(typeof(Native.ProgressFn))]
        static int ProgressThunk(IntPtr userdata, UIntPtr done, UIntPtr total)
        {
            // Nothing may unwind into native code: any exception cancels the run and is kept.
            Model model = null;
            try
            {
                model = (Model)GCHandle.FromIntPtr(userdata).Target;
                return model.progress((int)done, (int)total) ? 0 : 1;
            }
            catch (Exception e)
            {
                if (model != null) model.progressError = e;
                return 1;
            }
        }

        /// <summary>Calls `callback(done, total)` after each denoising step of the blocking
        /// tasks on this model; returning false (or throwing) stops the task, which then throws
        /// SinmdmCancelledException (the model stays usable). Null removes it.</summary>
        public void SetProgress(Func<int, int, bool> callback)
        {
            progress = callback;
            if (callback == null)
            {
                Native.Check(Native.sinmdm_model_set_progress(Handle, null, IntPtr.Zero));
                if (self.IsAllocated) self.Free();
                return;
            }
            if (!self.IsAllocated) self = GCHandle.Alloc(this, GCHandleType.Weak);
            Native.Check(Native.sinmdm_model_set_progress(Handle, Thunk, GCHandle.ToIntPtr(self)));
        }

        /// <summary>Throws for a failed task, as a cancellation when the callback stopped it.</summary>
        void CheckTask(int status)
        {
            Exception thrown = progressError;
            progressError = null;
            if (status == (int)Status.Cancelled)
                throw new SinmdmCancelledException(Native.LastError(), thrown);
            Native.Check(status);
        }

        public string JointName(int joint)
        {
            var index = Native.Size(joint, nameof(joint));
            Native.Check(Native.sinmdm_model_joint_name(Handle, index, null, UIntPtr.Zero, out UIntPtr needed));
            var buffer = new byte[(int)needed];
            Native.Check(Native.sinmdm_model_joint_name(Handle, index, buffer, needed, out needed));
            return Encoding.UTF8.GetString(buffer, 0, buffer.Length - 1);
        }

        public int FindJoint(string name)
        {
            Native.Check(Native.sinmdm_model_find_joint(Handle, Native.Utf8(name), out UIntPtr index));
            return (int)index;
        }

        /// <summary>Every joint's parent index (-1 for the root).</summary>
        public int[] Parents()
        {
            Native.Check(Native.sinmdm_model_parents(Handle, null, UIntPtr.Zero, out UIntPtr needed));
            var parents = new int[(int)needed];
            Native.Check(Native.sinmdm_model_parents(Handle, parents, needed, out needed));
            return parents;
        }

        /// <summary>Every joint's rest offset from its parent: x, y, z per joint (file units).</summary>
        public float[] RestOffsets()
        {
            Native.Check(Native.sinmdm_model_rest_offsets(Handle, null, UIntPtr.Zero, out UIntPtr needed));
            var offsets = new float[(int)needed];
            Native.Check(Native.sinmdm_model_rest_offsets(Handle, offsets, needed, out needed));
            return offsets;
        }

        /// <summary>The contact joints' indices (feet, paws).</summary>
        public int[] ContactJoints()
        {
            Native.Check(Native.sinmdm_model_contact_joints(Handle, null, UIntPtr.Zero, out UIntPtr needed));
            var joints = new UIntPtr[(int)needed];
            Native.Check(Native.sinmdm_model_contact_joints(Handle, joints, needed, out needed));
            return Array.ConvertAll(joints, j => (int)j);
        }

        Result Blocking(int status, ResultHandle handle)
        {
            if (status != 0) { handle.Dispose(); CheckTask(status); }
            // A callback that threw on the last step did not stop the run; what it threw is
            // dropped here so that it is not taken for the cause of a later cancel.
            progressError = null;
            try { return new Result(handle, Joints); }
            catch { handle.Dispose(); throw; }
        }

        /// <summary>New motion: `sampling.Count` samples of `frames` frames.</summary>
        public Result Generate(int frames, Sampling sampling)
        {
            var native = sampling.ToNative();
            int status = Native.sinmdm_generate(Handle, ref native, Native.Size(frames, nameof(frames)), out ResultHandle result);
            return Blocking(status, result);
        }

        /// <summary>New motion (the common case in one line).</summary>
        public Result Generate(int frames, ulong seed, int count = 1, uint steps = Runtime.DefaultSteps, Feet feet = Feet.Planted,
                               Method method = Method.Ancestral, double eta = 0.0) =>
            Generate(frames, new Sampling { Seed = seed, Count = count, Steps = steps, Feet = feet, Method = method, Eta = eta });

        /// <summary>Begins new motion, to step with Run.Step over a game's frames.</summary>
        public Run BeginGenerate(int frames, Sampling sampling)
        {
            var native = sampling.ToNative();
            int status = Native.sinmdm_generate_begin(Handle, ref native, Native.Size(frames, nameof(frames)), out RunHandle run);
            return Begun(status, run);
        }

        Run Begun(int status, RunHandle run)
        {
            if (status != 0) { run.Dispose(); Native.Check(status); }
            return new Run(run, this);
        }

        /// <summary>In-betweening: keep the spans of the reference given as start, end pairs
        /// (end excluded; an even count of numbers), fill the gaps.</summary>
        public Result Inbetween(Poses reference, int[] keep, int ramp, Sampling sampling)
        {
            var native = sampling.ToNative();
            var spans = Native.Spans(keep, nameof(keep));
            var r = Native.Size(ramp, nameof(ramp));
            ResultHandle result = null;
            int status = Native.WithInput(reference, Joints, input =>
                Native.sinmdm_inbetween(Handle, ref native, ref input, spans, (UIntPtr)spans.Length, r, out result));
            return Blocking(status, result);
        }

        public Result Inbetween(Poses reference, int[] keep, int ramp, ulong seed, uint steps = Runtime.DefaultSteps, Feet feet = Feet.Planted) =>
            Inbetween(reference, keep, ramp, new Sampling { Seed = seed, Count = 1, Steps = steps, Feet = feet });

        /// <summary>Begins an in-between, to step with Run.Step.</summary>
        public Run BeginInbetween(Poses reference, int[] keep, int ramp, Sampling sampling)
        {
            var native = sampling.ToNative();
            var spans = Native.Spans(keep, nameof(keep));
            var r = Native.Size(ramp, nameof(ramp));
            RunHandle run = null;
            int status = Native.WithInput(reference, Joints, input =>
                Native.sinmdm_inbetween_begin(Handle, ref native, ref input, spans, (UIntPtr)spans.Length, r, out run));
            return Begun(status, run);
        }

        /// <summary>The range of steering commands the model's clip supports; a model without a
        /// heading-relative root cannot be steered (SinmdmException, InvalidArgument).</summary>
        public SteerLimits SteerLimits()
        {
            Native.Check(Native.sinmdm_steer_limits(Handle, out Native.SteerLimits l));
            Native.Check(Native.sinmdm_steer_sideways_limits(Handle, out Native.SteerSideways s));
            return new SteerLimits { ForwardMin = l.ForwardMin, ForwardMax = l.ForwardMax, TurnMax = l.TurnMax, SidewaysMin = s.LeftwardMin, SidewaysMax = s.LeftwardMax };
        }

        /// <summary>New motion of `frames` frames whose root goes where `commands` say (one per
        /// frame from frame 0), soft over `ramp` frames where they start and stop.</summary>
        public Result Steer(int frames, SteerFrame[] commands, int ramp, Sampling sampling)
        {
            if (commands == null) throw new ArgumentNullException(nameof(commands));
            var native = sampling.ToNative();
            int status = Native.sinmdm_steer_commands(Handle, ref native, Native.Size(frames, nameof(frames)), commands,
                                             (UIntPtr)commands.Length, Native.Size(ramp, nameof(ramp)), out ResultHandle result);
            return Blocking(status, result);
        }

        public Result Steer(int frames, SteerFrame[] commands, int ramp, ulong seed, uint steps = Runtime.DefaultSteps, Feet feet = Feet.Planted) =>
            Steer(frames, commands, ramp, new Sampling { Seed = seed, Count = 1, Steps = steps, Feet = feet });

        /// <summary>Begins a steered run, to step with Run.Step.</summary>
        public Run BeginSteer(int frames, SteerFrame[] commands, int ramp, Sampling sampling)
        {
            if (commands == null) throw new ArgumentNullException(nameof(commands));
            var native = sampling.ToNative();
            int status = Native.sinmdm_steer_commands_begin(Handle, ref native, Native.Size(frames, nameof(frames)), commands,
                                                   (UIntPtr)commands.Length, Native.Size(ramp, nameof(ramp)), out RunHandle run);
            return Begun(status, run);
        }

        /// <summary>The beats of `reference` that a dance places: its speed minima on its own beat (frames).</summary>
        public int[] DanceReferenceBeats(Poses reference)
        {
            UIntPtr needed = UIntPtr.Zero;
            Native.Check(Native.WithInput(reference, Joints, input =>
                Native.sinmdm_dance_reference_beats(Handle, ref input, null, UIntPtr.Zero, out needed)));
            var beats = new UIntPtr[(int)needed];
            Native.Check(Native.WithInput(reference, Joints, input =>
                Native.sinmdm_dance_reference_beats(Handle, ref input, beats, (UIntPtr)beats.Length, out needed)));
            return Array.ConvertAll(beats, b => (int)b);
        }

        /// <summary>A dance: the reference's poses at its beats placed on the music's beats, the rest generated.</summary>
        public Result Dance(Poses reference, DanceSettings dance, Sampling sampling)
        {
            var native = sampling.ToNative();
            ResultHandle result = null;
            int status = Native.WithDance(dance, d => Native.WithInput(reference, Joints, input =>
                Native.sinmdm_dance(Handle, ref native, ref input, ref d, out result)));
            return Blocking(status, result);
        }

        public Result Dance(Poses reference, DanceSettings dance, ulong seed, uint steps = Runtime.DefaultSteps, Feet feet = Feet.Planted) =>
            Dance(reference, dance, new Sampling { Seed = seed, Count = 1, Steps = steps, Feet = feet });

        /// <summary>Begins a dance, to step with Run.Step.</summary>
        public Run BeginDance(Poses reference, DanceSettings dance, Sampling sampling)
        {
            var native = sampling.ToNative();
            RunHandle run = null;
            int status = Native.WithDance(dance, d => Native.WithInput(reference, Joints, input =>
                Native.sinmdm_dance_begin(Handle, ref native, ref input, ref d, out run)));
            return Begun(status, run);
        }

        /// <summary>Expansion: new frames before and after the reference.</summary>
        public Result Expand(Poses reference, int prefix, int suffix, int ramp, Sampling sampling)
        {
            var native = sampling.ToNative();
            UIntPtr p = Native.Size(prefix, nameof(prefix)), s = Native.Size(suffix, nameof(suffix)), r = Native.Size(ramp, nameof(ramp));
            ResultHandle result = null;
            int status = Native.WithInput(reference, Joints, input =>
                Native.sinmdm_expand(Handle, ref native, ref input, p, s, r, out result));
            return Blocking(status, result);
        }

        public Result Expand(Poses reference, int prefix, int suffix, int ramp, ulong seed, uint steps = Runtime.DefaultSteps, Feet feet = Feet.Planted) =>
            Expand(reference, prefix, suffix, ramp, new Sampling { Seed = seed, Count = 1, Steps = steps, Feet = feet });

        /// <summary>Begins an expansion, to step with Run.Step.</summary>
        public Run BeginExpand(Poses reference, int prefix, int suffix, int ramp, Sampling sampling)
        {
            var native = sampling.ToNative();
            UIntPtr p = Native.Size(prefix, nameof(prefix)), s = Native.Size(suffix, nameof(suffix)), r = Native.Size(ramp, nameof(ramp));
            RunHandle run = null;
            int status = Native.WithInput(reference, Joints, input =>
                Native.sinmdm_expand_begin(Handle, ref native, ref input, p, s, r, out run));
            return Begun(status, run);
        }

        /// <summary>Composition: the joints (and the root's travel when root) from the reference
        /// on the spans (start, end pairs; null or empty: every frame), the rest generated.</summary>
        public Result Compose(Poses reference, int[] joints, bool root, int[] spans, int ramp, Sampling sampling)
        {
            var native = sampling.ToNative();
            var indices = Native.Indices(joints, nameof(joints));
            var kept = Native.Spans(spans, nameof(spans));
            var r = Native.Size(ramp, nameof(ramp));
            ResultHandle result = null;
            int status = Native.WithInput(reference, Joints, input =>
                Native.sinmdm_compose(Handle, ref native, ref input, indices, (UIntPtr)indices.Length, root ? 1 : 0,
                                      kept, (UIntPtr)kept.Length, r, out result));
            return Blocking(status, result);
        }

        public Result Compose(Poses reference, int[] joints, bool root, int ramp, ulong seed, uint steps = Runtime.DefaultSteps, Feet feet = Feet.Planted) =>
            Compose(reference, joints, root, null, ramp, new Sampling { Seed = seed, Count = 1, Steps = steps, Feet = feet });

        /// <summary>Begins a composition, to step with Run.Step.</summary>
        public Run BeginCompose(Poses reference, int[] joints, bool root, int[] spans, int ramp, Sampling sampling)
        {
            var native = sampling.ToNative();
            var indices = Native.Indices(joints, nameof(joints));
            var kept = Native.Spans(spans, nameof(spans));
            var r = Native.Size(ramp, nameof(ramp));
            RunHandle run = null;
            int status = Native.WithInput(reference, Joints, input =>
                Native.sinmdm_compose_begin(Handle, ref native, ref input, indices, (UIntPtr)indices.Length, root ? 1 : 0,
                                            kept, (UIntPtr)kept.Length, r, out run));
            return Begun(status, run);
        }

        /// <summary>Harmonization (style transfer): the content's low frequencies in the model's style.</summary>
        public Result Harmonize(Poses content, int factor, double freeShare, Sampling sampling)
        {
            var native = sampling.ToNative();
            var f = Native.Size(factor, nameof(factor));
            ResultHandle result = null;
            int status = Native.WithInput(content, Joints, input =>
                Native.sinmdm_harmonize(Handle, ref native, ref input, f, freeShare, out result));
            return Blocking(status, result);
        }

        public Result Harmonize(Poses content, int factor, double freeShare, ulong seed, uint steps = Runtime.DefaultSteps, Feet feet = Feet.Planted) =>
            Harmonize(content, factor, freeShare, new Sampling { Seed = seed, Count = 1, Steps = steps, Feet = feet });

        /// <summary>Begins a harmonization, to step with Run.Step.</summary>
        public Run BeginHarmonize(Poses content, int factor, double freeShare, Sampling sampling)
        {
            var native = sampling.ToNative();
            var f = Native.Size(factor, nameof(factor));
            RunHandle run = null;
            int status = Native.WithInput(content, Joints, input =>
                Native.sinmdm_harmonize_begin(Handle, ref native, ref input, f, freeShare, out run));
            return Begun(status, run);
        }

        /// <summary>Writes poses of this model's skeleton as a BVH file.</summary>
        public void WriteBvh(Poses poses, string path)
        {
            var p = Native.Utf8(path);
            Native.Check(Native.WithInput(poses, Joints, input => Native.sinmdm_write_bvh(Handle, ref input, p)));
        }

        public void Dispose()
        {
            Handle.Dispose();
            if (self.IsAllocated) self.Free();
            GC.SuppressFinalize(this);
        }

        /// <summary>A model never disposed: its native handle is freed by its SafeHandle's own
        /// finalizer; this frees the callback's GCHandle.</summary>
        ~Model()
        {
            if (self.IsAllocated) self.Free();
        }
    }

    /// <summary>A task being run a few steps at a time (a game's frame budget): Step until
    /// done, then Finish; Dispose before that cancels it. The bits are the one-call task's.</summary>
    public sealed class Run : IDisposable
    {
        readonly RunHandle handle;
        readonly Model model;
        public int Done { get; private set; }
        public int Total { get; private set; }
        public bool IsFinished => Total > 0 && Done >= Total;

        internal Run(RunHandle handle, Model model) { this.handle = handle; this.model = model; }

        /// <summary>Takes at most `maxSteps` denoising steps; returns whether every step is taken.</summary>
        public bool Step(int maxSteps)
        {
            Native.Check(Native.sinmdm_run_step(handle, model.Handle, Native.Size(maxSteps, nameof(maxSteps)), out UIntPtr done, out UIntPtr total));
            Done = (int)done;
            Total = (int)total;
            return IsFinished;
        }

        /// <summary>The batch: the motion once every step is taken, a preview before that.</summary>
        public Result Finish()
        {
            int status = Native.sinmdm_run_finish(handle, out ResultHandle result);
            if (status != 0) { result.Dispose(); Native.Check(status); }
            return new Result(result, model.Joints);
        }

        public void Dispose() => handle.Dispose();
    }

    /// <summary>A generated batch.</summary>
    public sealed class Result : IDisposable
    {
        readonly ResultHandle handle;
        readonly int joints;
        public readonly int Count, Frames;

        internal Result(ResultHandle handle, int joints)
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
            var index = Native.Size(sample, nameof(sample));
            var poses = new Poses(Frames, joints);
            Native.Check(Native.WithBuffers(poses, b => Native.sinmdm_result_poses(handle, index, ref b)));
            return poses;
        }

        public void Dispose() => handle.Dispose();
    }

    /// <summary>How a motion stream makes its motion.</summary>
    public struct StreamSettings
    {
        public ulong Seed;
        public uint Steps, BlockFrames;
        public Feet Feet;
        public Method Method;
        public double Eta;
        /// <summary>Joints taken from poses given with Supply (null: none).</summary>
        public int[] ComposeJoints;
        /// <summary>Whether the root's travel and height also come from the supplied poses.</summary>
        public bool ComposeRoot;

        internal delegate T WithOptions<T>(ref Native.StreamOptions options);

        /// <summary>Calls `call` with these settings as the native struct, the joint array
        /// pinned for the call only.</summary>
        internal T Pinned<T>(WithOptions<T> call)
        {
            var joints = Native.Indices(ComposeJoints, nameof(ComposeJoints));
            var pinned = GCHandle.Alloc(joints, GCHandleType.Pinned);
            try
            {
                var options = new Native.StreamOptions
                {
                    Seed = Seed, Steps = Steps, BlockFrames = BlockFrames, Feet = (uint)Feet,
                    ComposeJoints = joints.Length > 0 ? pinned.AddrOfPinnedObject() : IntPtr.Zero,
                    ComposeJointCount = (UIntPtr)joints.Length, ComposeRoot = ComposeRoot ? 1 : 0,
                    Method = (uint)Method, Eta = Eta,
                };
                return call(ref options);
            }
            finally { pinned.Free(); }
        }
    }

    /// <summary>Endless motion, a chunk at a time (the same whatever chunk sizes are asked).
    /// Named so as not to clash with System.IO.Stream.</summary>
    /// <summary>Many characters of one model, each an endless stream, made together: one
    /// network call per step for the whole crowd, each character the same bits as its
    /// MotionStream alone. Characters join and leave at any frame.</summary>
    public sealed class Crowd : IDisposable
    {
        readonly CrowdHandle handle;
        readonly Model model;

        public Crowd(Model model)
        {
            if (model == null) throw new ArgumentNullException(nameof(model));
            this.model = model;
            int status = Native.sinmdm_crowd_new(model.Handle, out handle);
            if (status != 0) { handle.Dispose(); Native.Check(status); }
        }

        /// <summary>A new character with a stream's settings; its number, never given again.</summary>
        public ulong Join(StreamSettings settings) =>
            settings.Pinned((ref Native.StreamOptions options) =>
            {
                Native.Check(Native.sinmdm_crowd_join(handle, ref options, out ulong id));
                return id;
            });

        /// <summary>Takes character `id` out of the crowd.</summary>
        public void Leave(ulong id) => Native.Check(Native.sinmdm_crowd_leave(handle, id));

        /// <summary>Characters in the crowd.</summary>
        public int Count
        {
            get { Native.Check(Native.sinmdm_crowd_count(handle, out UIntPtr count)); return (int)count; }
        }

        /// <summary>Character `id`'s steering commands, as MotionStream.Steer takes them.</summary>
        public void Steer(ulong id, SteerFrame[] commands)
        {
            if (commands == null) throw new ArgumentNullException(nameof(commands));
            Native.Check(Native.sinmdm_crowd_steer(handle, id, commands, (UIntPtr)commands.Length));
        }

        /// <summary>Character `id`'s poses for the frames after the last supplied ones.</summary>
        public void Supply(ulong id, Poses poses) =>
            Native.Check(Native.WithInput(poses, model.Joints, input => Native.sinmdm_crowd_supply(handle, model.Handle, id, ref input)));

        /// <summary>Prepares frames ahead with at most `maxSteps` denoising steps, one step of
        /// one character each (call it each frame): characters with fewer than `ahead` frames
        /// ready step, the fewest ready first; returns the characters still short of `ahead`.</summary>
        public int Prepare(int maxSteps, int ahead)
        {
            Native.Check(Native.sinmdm_crowd_step(handle, model.Handle, Native.Size(maxSteps, nameof(maxSteps)),
                                                  Native.Size(ahead, nameof(ahead)), out UIntPtr steps, out UIntPtr waiting));
            return (int)waiting;
        }

        /// <summary>Character `id`'s next `frames` frames.</summary>
        public Poses Next(ulong id, int frames)
        {
            var n = Native.Size(frames, nameof(frames));
            var poses = new Poses(frames, model.Joints);
            Native.Check(Native.WithBuffers(poses, b => Native.sinmdm_crowd_next(handle, model.Handle, id, n, ref b)));
            return poses;
        }

        public void Dispose() => handle.Dispose();
    }

    public sealed class MotionStream : IDisposable
    {
        readonly StreamHandle handle;
        readonly Model model;

        public MotionStream(Model model, StreamSettings settings)
        {
            if (model == null) throw new ArgumentNullException(nameof(model));
            this.model = model;
            handle = settings.Pinned((ref Native.StreamOptions options) =>
            {
                int status = Native.sinmdm_stream_new(model.Handle, ref options, out StreamHandle made);
                if (status != 0) { made.Dispose(); Native.Check(status); }
                return made;
            });
        }

        public MotionStream(Model model, ulong seed, uint steps = Runtime.DefaultStreamSteps, uint blockFrames = 0, Feet feet = Feet.Planted,
                            Method method = Method.Ancestral, double eta = 0.0)
            : this(model, new StreamSettings { Seed = seed, Steps = steps, BlockFrames = blockFrames, Feet = feet, Method = method, Eta = eta }) { }

        /// <summary>Poses for the frames after the last supplied ones, for a composed stream.</summary>
        public void Supply(Poses poses) =>
            Native.Check(Native.WithInput(poses, model.Joints, input => Native.sinmdm_stream_supply(handle, model.Handle, ref input)));

        /// <summary>Steering commands for the frames after the last commanded ones (a
        /// heading-relative model; command i given in all is stream frame i). Give them at least
        /// 2 x block + 10 frames ahead of what was handed out, plus what Prepare made ahead.</summary>
        public void Steer(SteerFrame[] commands)
        {
            if (commands == null) throw new ArgumentNullException(nameof(commands));
            Native.Check(Native.sinmdm_stream_steer_commands(handle, commands, (UIntPtr)commands.Length));
        }

        /// <summary>Prepares frames ahead with at most `maxSteps` denoising steps (call it each
        /// frame); returns the frames ready, so Next for that many runs no network.</summary>
        public int Prepare(int maxSteps, int ahead)
        {
            Native.Check(Native.sinmdm_stream_step(handle, model.Handle, Native.Size(maxSteps, nameof(maxSteps)),
                                                   Native.Size(ahead, nameof(ahead)), out UIntPtr ready, out UIntPtr done, out UIntPtr total));
            return (int)ready;
        }

        public Poses Next(int frames)
        {
            var n = Native.Size(frames, nameof(frames));
            var poses = new Poses(frames, model.Joints);
            Native.Check(Native.WithBuffers(poses, b => Native.sinmdm_stream_next(handle, model.Handle, n, ref b)));
            return poses;
        }

        public void Dispose() => handle.Dispose();
    }
}
