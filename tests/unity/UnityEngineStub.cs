// The few UnityEngine types the package's Runtime/ uses, as empty stand-ins, so CI can compile
// the package's scripts with mcs where Unity is not installed. Signatures follow Unity's.
using System;

namespace UnityEngine
{
    public class Object { public string name; }
    public class Component : Object
    {
        public Transform transform;
        public GameObject gameObject;
        public T[] GetComponentsInChildren<T>() { return new T[0]; }
    }
    public class Behaviour : Component { }
    public class MonoBehaviour : Behaviour { }
    public class GameObject : Object { public T AddComponent<T>() where T : Component, new() { return new T(); } }
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
