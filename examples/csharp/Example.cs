// A console program over the C# binding: a crowd, an in-between and a stream, each value
// printed as the bits of its float (the tests compare them with the Rust API's), and a BVH.
// `using System.IO;` is there on purpose: the binding's names must not clash with System's.
//
//   mcs -out:example.exe bindings/csharp/*.cs examples/csharp/Example.cs
//   LD_LIBRARY_PATH=target/release mono example.exe onnx-models/human_walk_cmu.onnx out.bvh
using System;
using System.IO;
using System.Text;
using Sinmdm;

static class Example
{
    static void Print(string label, float[] values)
    {
        var line = new StringBuilder(label);
        foreach (float v in values)
            line.Append(' ').Append(BitConverter.ToUInt32(BitConverter.GetBytes(v), 0).ToString("x8"));
        Console.WriteLine(line);
    }

    static void Print(string label, Poses poses)
    {
        Print(label + ".root", poses.RootPositions);
        Print(label + ".rotations", poses.Rotations);
        Print(label + ".translations", poses.Translations);
    }

    static int Main(string[] args)
    {
        if (args.Length != 3)
        {
            Console.Error.WriteLine("usage: example.exe MODEL.onnx OUT.bvh STEERABLE_MODEL.onnx");
            return 2;
        }
        using (var model = Model.Open(args[0], 1))
        {
            Console.WriteLine("info joints=" + model.Joints + " root=" + model.JointName(0));
            Poses first;
            using (var crowd = model.Generate(40, seed: 7, count: 2, steps: 4))
            {
                first = crowd.Poses(0);
                Print("generate1", crowd.Poses(1));
            }
            using (var quick = model.Generate(40, seed: 5, steps: 8, feet: Feet.Raw, method: Method.DpmSolver2M))
                Print("dpm2m", quick.Poses(0));
            using (var byDefault = model.Generate(30, seed: 9, feet: Feet.Raw))
                Print("default_steps", byDefault.Poses(0));
            using (var between = model.Inbetween(first, new[] { 0, 10, 30, 40 }, 5, seed: 3, steps: 4))
                Print("inbetween", between.Poses(0));
            int beatStatus = 0, beatCount = 0;
            try { beatCount = model.DanceReferenceBeats(first).Length; }
            catch (SinmdmException e) { beatStatus = (int)e.Status; }
            Print("dancebeats.status", new float[] { beatStatus, beatCount });
            var dance = new DanceSettings
            {
                ReferenceBeats = new[] { 8, 20, 32 }, MusicBeats = new[] { 5, 17, 29, 41 }, Frames = 50,
                Ramp = 3, Order = DanceOrder.Shuffled,
            };
            using (var danced = model.Dance(first, dance, seed: 3, steps: 4))
                Print("dance", danced.Poses(0));
            using (var expanded = model.Expand(first, 5, 7, 3, seed: 2, steps: 3))
            using (var composed = model.Compose(first, new[] { 1, 2 }, true, 5, seed: 2, steps: 3))
            using (var styled = model.Harmonize(first, 2, 0.02, seed: 2, steps: 3))
                Console.WriteLine("tasks expand=" + expanded.Frames + " compose=" + composed.Frames + " harmonize=" + styled.Frames);
            using (var stream = new MotionStream(model, seed: 11, steps: 3, blockFrames: 30))
            {
                Print("stream20", stream.Next(20));
                Print("stream25", stream.Next(25));
            }
            try
            {
                model.FindJoint("NoSuchJoint");
                Console.WriteLine("no error for an unknown joint");
                return 1;
            }
            catch (SinmdmException e)
            {
                Console.WriteLine("unknown joint: status " + (int)e.Status);
            }
            model.WriteBvh(first, args[1]);
        }
        // Steering a heading-relative model: 40 frames at 12 units/s turning 0.3 rad/s, and a
        // stream told 10 units/s turning -0.2 rad/s.
        using (var zombie = Model.Open(args[2], 1))
        {
            var limits = zombie.SteerLimits();
            Console.WriteLine("steer limits forward " + limits.ForwardMin.ToString("F2") + " to " + limits.ForwardMax.ToString("F2")
                + " sideways " + limits.SidewaysMin.ToString("F2") + " to " + limits.SidewaysMax.ToString("F2"));
            var ahead = new SteerFrame[40];
            for (int i = 0; i < ahead.Length; i++) ahead[i] = SteerFrame.Velocity(12.0, 0.3);
            using (var steered = zombie.Steer(40, ahead, 5, seed: 3, steps: 4))
                Print("steer", steered.Poses(0));
            // Facing commands: 20 frames facing (1, 0.5) on the ground (+Z is up), then 20 at
            // positions (0.5 i, 0.2 i) facing +Y.
            var faced = new SteerFrame[40];
            for (int i = 0; i < faced.Length; i++)
                faced[i] = i < 20 ? SteerFrame.Facing(1.0, 0.5, 0.0) : SteerFrame.PositionFacing(0.5 * i, 0.2 * i, 0.0, 0.0, 1.0, 0.0);
            using (var steered = zombie.Steer(40, faced, 5, seed: 3, steps: 4))
                Print("steerfacing", steered.Poses(0));
            using (var stream = new MotionStream(zombie, seed: 11, steps: 3, blockFrames: 30))
            {
                var told = new SteerFrame[60];
                for (int i = 0; i < told.Length; i++) told[i] = SteerFrame.Velocity(10.0, -0.2);
                stream.Steer(told);
                Print("steerstream20", stream.Next(20));
                Print("steerstream25", stream.Next(25));
            }
            // A crowd: the steered character is the same bits as the stream above, whoever
            // else is in the crowd.
            using (var crowd = new Crowd(zombie))
            {
                var stranger = crowd.Join(new StreamSettings { Seed = 12, Steps = 3, BlockFrames = 30, Feet = Feet.Raw });
                var walker = crowd.Join(new StreamSettings { Seed = 11, Steps = 3, BlockFrames = 30 });
                var told = new SteerFrame[60];
                for (int i = 0; i < told.Length; i++) told[i] = SteerFrame.Velocity(10.0, -0.2);
                crowd.Steer(walker, told);
                while (crowd.Prepare(4, 45) > 0) { }
                Print("crowdsteer20", crowd.Next(walker, 20));
                crowd.Leave(stranger);
                Print("crowdsteer25", crowd.Next(walker, 25));
            }
        }
        return 0;
    }
}
