// The few UnityEngine types the package's Runtime/ uses, as stand-ins, so CI can compile the
// package's scripts with mcs where Unity is not installed, and run its components headless
// (tests/unity/CrowdCheck.cs). Signatures follow Unity's.
using System;

namespace UnityEngine
{
    public class Object { public string name; }
    public class Component : Object
    {
        public Transform transform;
        public GameObject gameObject;
        public T[] GetComponentsInChildren<T>() { return gameObject != null ? gameObject.GetComponentsInChildren<T>() : new T[0]; }
    }
    public class Behaviour : Component { }
    public class MonoBehaviour : Behaviour { }
    // A game object holds its components, its children's flattened into it (enough for a rig
    // whose bones are found by name).
    public class GameObject : Object
    {
        readonly System.Collections.Generic.List<Component> components = new System.Collections.Generic.List<Component>();
        public T AddComponent<T>() where T : Component, new() { var c = new T(); c.gameObject = this; components.Add(c); return c; }
        public T[] GetComponentsInChildren<T>()
        {
            var found = new System.Collections.Generic.List<T>();
            foreach (var c in components) if (c is T t) found.Add(t);
            return found.ToArray();
        }
    }
    public class Transform : Component
    {
        public Quaternion localRotation;
        public Vector3 localPosition;
    }
    public class TextAsset : Object { public byte[] bytes; }
    public struct Vector3 { public float x, y, z; public Vector3(float x, float y, float z) { this.x = x; this.y = y; this.z = z; } }
    public struct Quaternion { public float x, y, z, w; public Quaternion(float x, float y, float z, float w) { this.x = x; this.y = y; this.z = z; this.w = w; } }
    public static class Time { public static float deltaTime; }
    public static class Mathf { public static int Max(int a, int b) { return a > b ? a : b; } }
    public static class Debug { public static void LogWarning(object message) { } }
    [AttributeUsage(AttributeTargets.Field)] public sealed class TooltipAttribute : Attribute { public TooltipAttribute(string tooltip) { } }
}

namespace AOT
{
    [AttributeUsage(AttributeTargets.Method)]
    public sealed class MonoPInvokeCallbackAttribute : Attribute { public MonoPInvokeCallbackAttribute(Type type) { } }
}
