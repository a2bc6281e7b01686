// The C# binding's promises under Mono: a run stepped 1, 3 or all steps at a time gives the
// one-call bits; a progress callback cancels at step k and the model goes on working; a
// callback that throws cancels instead of unwinding through native frames (its exception is
// the cancellation's InnerException); a model never disposed is freed by its finalizer; odd
// span arrays and negative sizes are refused before any native call; a prepared stream equals
// a blocking one. Prints "csharp checks: N passed" or the failures, and exits non-zero on one.
using System;
using System.IO;
using Sinmdm;

static class Checks
{
    static int passed, failed;

    static void Expect(bool ok, string what)
    {
        if (ok) passed++;
        else { failed++; Console.WriteLine("FAILED: " + what); }
    }

    static bool Same(Poses a, Poses b)
    {
        if (a.Frames != b.Frames) return false;
        for (int i = 0; i < a.Rotations.Length; i++)
            if (BitConverter.ToInt32(BitConverter.GetBytes(a.Rotations[i]), 0) != BitConverter.ToInt32(BitConverter.GetBytes(b.Rotations[i]), 0)) return false;
        for (int i = 0; i < a.RootPositions.Length; i++)
            if (a.RootPositions[i] != b.RootPositions[i]) return false;
        return true;
    }

    static void OpenAndForget(string path)
    {
        var model = Model.Open(path, 1);
        model.SetProgress((done, total) => true);
    }

    static int Main(string[] args)
    {
        string path = args[0];
        long before = Runtime.LiveHandles;
        var sampling = new Sampling { Seed = 13, Count = 1, Steps = 7, Feet = Feet.Planted };
        using (var model = Model.Open(path, 2))
        {
            Poses once;
            using (var result = model.Generate(40, sampling)) once = result.Poses(0);
            foreach (int perCall in new[] { 1, 3, int.MaxValue })
            {
                using (var run = model.BeginGenerate(40, sampling))
                {
                    int calls = 0;
                    while (!run.Step(perCall)) calls++;
                    using (var result = run.Finish())
                        Expect(Same(result.Poses(0), once), "stepped " + perCall + " at a time gives the one-call bits");
                    Expect(run.Total == 7 && run.Done == 7, "a run says 7 of 7 steps");
                }
            }
            using (var run = model.BeginGenerate(40, sampling))
            {
                run.Step(3);
                using (var preview = run.Finish())
                    Expect(!Same(preview.Poses(0), once), "a run finished early gives a preview");
            }

            int seen = 0;
            model.SetProgress((done, total) => { seen = done; return done < 3; });
            try { model.Generate(40, sampling).Dispose(); Expect(false, "cancel at step 3 throws"); }
            catch (SinmdmCancelledException e) { Expect(seen == 3 && e.Status == Status.Cancelled && e.InnerException == null, "cancelled at step 3"); }

            model.SetProgress((done, total) => { if (done == 2) throw new InvalidOperationException("from the callback"); return true; });
            try { model.Generate(40, sampling).Dispose(); Expect(false, "a throwing callback cancels"); }
            catch (SinmdmCancelledException e) { Expect(e.InnerException is InvalidOperationException, "the callback's exception is kept, not unwound"); }

            model.SetProgress(null);
            using (var result = model.Generate(40, sampling))
                Expect(Same(result.Poses(0), once), "the model works on after a cancel");

            try { model.Inbetween(once, new[] { 0, 10, 30 }, 5, sampling); Expect(false, "odd keep refused"); }
            catch (ArgumentException) { passed++; }
            try { model.Expand(new Poses(40, model.Joints - 1), 5, 5, 3, sampling); Expect(false, "poses of another skeleton refused"); }
            catch (ArgumentException) { passed++; }
            try { model.Generate(-5, sampling); Expect(false, "negative frames refused"); }
            catch (ArgumentOutOfRangeException) { passed++; }
            try { model.Generate(40, new Sampling { Seed = 1, Count = 0 }); Expect(false, "zero samples refused"); }
            catch (ArgumentOutOfRangeException) { passed++; }
            try { model.JointName(100000); Expect(false, "a joint out of range throws"); }
            catch (SinmdmException e) { Expect(e.Status == Status.InvalidArgument, "a joint out of range is InvalidArgument"); }
            Expect(model.Parents().Length == model.Joints && model.Parents()[0] == -1, "parents by size query");
            Expect(model.RestOffsets().Length == 3 * model.Joints, "rest offsets by size query");
            Expect(model.ContactJoints().Length == (int)model.Info.ContactJoints, "contact joints by size query");
            foreach (var begun in new Func<Run>[] {
                () => model.BeginExpand(once, 5, 5, 3, sampling),
                () => model.BeginCompose(once, new[] { 1, 2 }, true, new[] { 0, 20 }, 3, sampling),
                () => model.BeginHarmonize(once, 2, 0.1, sampling) })
                using (var run = begun())
                {
                    while (!run.Step(4)) { }
                    using (var result = run.Finish()) Expect(result.Frames >= 40, "a begun task steps to its end");
                }

            var settings = new StreamSettings { Seed = 11, Steps = 3, BlockFrames = 30, Feet = Feet.Planted };
            using (var blocking = new MotionStream(model, settings))
            using (var prepared = new MotionStream(model, settings))
            {
                foreach (int n in new[] { 20, 45 })
                {
                    var want = blocking.Next(n);
                    int frames = 0;
                    while (prepared.Prepare(1, n) < n && frames < 100) frames++;
                    Expect(Same(prepared.Next(n), want), "a prepared stream gives the blocking bits (" + n + ")");
                }
            }
            using (var composed = new MotionStream(model, new StreamSettings { Seed = 2, Steps = 2, BlockFrames = 30, ComposeJoints = new[] { 1, 2 }, Eta = 0.5, Method = Method.Ddim }))
            {
                composed.Supply(once);
                Expect(composed.Next(10).Frames == 10, "a composed DDIM stream runs");
            }
            // System.IO.Stream and Sinmdm.MotionStream live side by side.
            using (System.IO.Stream memory = new MemoryStream()) memory.WriteByte(1);
        }
        OpenAndForget(path);
        GC.Collect();
        GC.WaitForPendingFinalizers();
        GC.Collect();
        GC.WaitForPendingFinalizers();
        Expect(Runtime.LiveHandles == before, "every handle freed, the forgotten model by its finalizer (" + Runtime.LiveHandles + " alive)");
        Console.WriteLine("csharp checks: " + passed + " passed, " + failed + " failed");
        return failed == 0 ? 0 : 1;
    }
}
