// The Unity crowd component run headless under Mono against the UnityEngine stand-ins: eight
// rigs of the shipped walk driven by one SinmdmCrowdAnimator for four seconds at 60 frames a
// second, told to turn right, not at all and left in turn. Every character moves, the turners
// turn opposite ways by more than a radian and more than any straight walker, and character 0's
// last pose is bit for bit a steered MotionStream of its own with the same seed and commands.
// Prints "unity crowd checks: N passed" or the failures, and exits non-zero on one.
using System;
using System.IO;
using System.Reflection;
using Sinmdm;
using UnityEngine;

static class CrowdCheck
{
    static int passed, failed;

    static void Expect(bool ok, string what)
    {
        if (ok) passed++;
        else { failed++; Console.WriteLine("FAILED: " + what); }
    }

    static void Call(object target, string method) =>
        target.GetType().GetMethod(method, BindingFlags.Instance | BindingFlags.NonPublic).Invoke(target, null);

    static double Heading(Vector3 from, Vector3 to) => Math.Atan2(to.x - from.x, to.z - from.z);

    static double Wrapped(double a)
    {
        while (a > Math.PI) a -= 2 * Math.PI;
        while (a <= -Math.PI) a += 2 * Math.PI;
        return a;
    }

    static int Main(string[] args)
    {
        byte[] bytes = File.ReadAllBytes(args[0]);
        const int n = 8, updates = 240, half = 30;
        string[] joints;
        double clipSpeed;
        using (var model = Model.FromBytes(bytes, 1))
        {
            var limits = model.SteerLimits();
            clipSpeed = 0.5 * (limits.ForwardMin + limits.ForwardMax);
            joints = new string[model.Joints];
            for (int j = 0; j < joints.Length; j++) joints[j] = model.JointName(j);
        }
        var manager = new GameObject { name = "crowd" };
        var crowd = manager.AddComponent<SinmdmCrowdAnimator>();
        crowd.model = new TextAsset { bytes = bytes };
        crowd.seed = 5;
        crowd.stepsPerCharacter = 4;
        crowd.characters = new GameObject[n];
        crowd.turns = new float[n];
        var roots = new Transform[n];
        for (int i = 0; i < n; i++)
        {
            var rig = new GameObject { name = "walker" + i };
            foreach (var name in joints) rig.AddComponent<Transform>().name = name;
            crowd.characters[i] = rig;
            crowd.turns[i] = 0.9f * (i % 3 - 1);
            roots[i] = rig.GetComponentsInChildren<Transform>()[0];
        }
        Call(crowd, "Start");
        Time.deltaTime = 1f / 60f;
        var path = new Vector3[n, updates];
        for (int u = 0; u < updates; u++)
        {
            Call(crowd, "Update");
            for (int i = 0; i < n; i++) path[i, u] = roots[i].localPosition;
        }
        int played = crowd.FramesPlayed;
        Expect(played >= 100, "the crowd played " + played + " model frames in four seconds");

        // Turns between the directions of travel over the first and last half-seconds of the
        // last three seconds.
        var turned = new double[n];
        int start = updates - 6 * half;
        for (int i = 0; i < n; i++)
        {
            double before = Heading(path[i, start], path[i, start + half]);
            double after = Heading(path[i, updates - 1 - half], path[i, updates - 1]);
            turned[i] = Wrapped(after - before);
            Console.WriteLine("character " + i + " told " + crowd.turns[i] + " rad/s: turned " + turned[i].ToString("F2") + " rad");
            var d = path[i, updates - 1];
            var s = path[i, start];
            double walked = Math.Sqrt((d.x - s.x) * (d.x - s.x) + (d.z - s.z) * (d.z - s.z));
            // Told to walk at the clip's mean speed for 3 s: at least half as far, in a line or not.
            double least = 0.5 * 3.0 * clipSpeed * crowd.metresPerUnit;
            Console.WriteLine("character " + i + " walked " + walked.ToString("F2") + " m in 3 s (at least " + least.ToString("F2") + ")");
            Expect(walked > least, "character " + i + " walks");
        }
        double sign = Math.Sign(turned[2]);
        for (int i = 0; i < n; i++)
        {
            if (i % 3 == 1) Expect(Math.Abs(turned[i]) < 1.0, "straight walker " + i + " turned " + turned[i]);
            else
            {
                double expected = (i % 3 == 2 ? 1 : -1) * sign;
                Expect(turned[i] * expected > 1.0, "turner " + i + " turned " + turned[i]);
            }
        }

        // Character 0 alone: a stream with its seed and commands, read up to the frame shown.
        using (var model = Model.FromBytes(bytes, 1))
        using (var alone = new MotionStream(model, new StreamSettings { Seed = 5, Feet = Feet.Planted }))
        {
            var limits = model.SteerLimits();
            var told = new SteerFrame[4 * (int)model.Info.ClipFrames + 4 * (int)model.Info.Fps + played];
            for (int k = 0; k < told.Length; k++) told[k] = SteerFrame.Velocity(0.5 * (limits.ForwardMin + limits.ForwardMax), crowd.turns[0]);
            alone.Steer(told);
            Poses poses = alone.Next(played);
            var root = new float[3];
            Array.Copy(poses.RootPositions, 3 * (played - 1), root, 0, 3);
            Coordinates.ToUnityPosition(model.Info, root, 0, crowd.metresPerUnit);
            var shown = roots[0].localPosition;
            Expect(root[0] == shown.x && root[1] == shown.y && root[2] == shown.z,
                   "character 0 is its stream alone: (" + shown.x + ", " + shown.y + ", " + shown.z + ") against (" + root[0] + ", " + root[1] + ", " + root[2] + ")");
        }
        Call(crowd, "OnDestroy");
        Console.WriteLine("unity crowd checks: " + passed + " passed, " + failed + " failed");
        return failed == 0 ? 0 : 1;
    }
}
