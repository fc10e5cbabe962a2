// tests/scene/json_schema.h: a JSON Schema validator for the keywords scenes/scene.schema.json
// uses (draft 2020-12 meaning; Debian 12 packages no C++ validator). A schema using any other
// keyword is refused, so the schema cannot rely on a rule this validator would silently skip.
#pragma once

#include <cmath>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace shadowlab::test {

class SchemaValidator {
public:
    using Json = nlohmann::json;

    explicit SchemaValidator(Json root) : root_(std::move(root)) { checkKeywords(root_, "#"); }

    // Every violation as "PATH: what" (PATH like objects[2].radius); empty when valid.
    std::vector<std::string> validate(const Json& doc) const {
        std::vector<std::string> errors;
        check(root_, doc, "", errors);
        return errors;
    }

private:
    static const std::set<std::string>& keywords() {
        static const std::set<std::string> k = {"$schema",
                                                "$id",
                                                "$defs",
                                                "$ref",
                                                "title",
                                                "description",
                                                "default",
                                                "examples",
                                                "type",
                                                "properties",
                                                "required",
                                                "additionalProperties",
                                                "minProperties",
                                                "items",
                                                "minItems",
                                                "maxItems",
                                                "enum",
                                                "const",
                                                "minimum",
                                                "maximum",
                                                "exclusiveMinimum",
                                                "exclusiveMaximum",
                                                "minLength",
                                                "allOf",
                                                "anyOf",
                                                "oneOf",
                                                "not",
                                                "if",
                                                "then",
                                                "else"};
        return k;
    }

    static void checkKeywords(const Json& s, const std::string& where) {
        if (s.is_boolean()) return;
        if (!s.is_object()) throw std::invalid_argument(where + ": a schema must be an object or a boolean");
        for (const auto& [key, value] : s.items()) {
            if (!keywords().count(key)) throw std::invalid_argument(where + ": unsupported keyword '" + key + "'");
            if (key == "properties" || key == "$defs")
                for (const auto& [name, sub] : value.items()) checkKeywords(sub, where + "/" + key + "/" + name);
            if (key == "additionalProperties" || key == "items" || key == "not" || key == "if" || key == "then" ||
                key == "else")
                checkKeywords(value, where + "/" + key);
            if (key == "allOf" || key == "anyOf" || key == "oneOf")
                for (std::size_t i = 0; i < value.size(); ++i)
                    checkKeywords(value[i], where + "/" + key + "/" + std::to_string(i));
        }
    }

    const Json& resolve(const std::string& ref) const {
        if (ref.rfind("#/", 0) != 0) throw std::invalid_argument("only local $ref are supported: " + ref);
        const Json* node = &root_;
        std::size_t at = 2;
        while (at <= ref.size()) {
            const std::size_t slash = std::min(ref.find('/', at), ref.size());
            const std::string part = ref.substr(at, slash - at);
            if (!node->is_object() || !node->contains(part)) throw std::invalid_argument("unresolved $ref " + ref);
            node = &(*node)[part];
            at = slash + 1;
        }
        return *node;
    }

    static bool hasType(const Json& v, const std::string& type) {
        if (type == "object") return v.is_object();
        if (type == "array") return v.is_array();
        if (type == "string") return v.is_string();
        if (type == "boolean") return v.is_boolean();
        if (type == "null") return v.is_null();
        if (type == "number") return v.is_number();
        if (type == "integer")  // 2020-12: any number with a zero fractional part
            return v.is_number_integer() || (v.is_number_float() && std::floor(v.get<double>()) == v.get<double>());
        throw std::invalid_argument("unknown type '" + type + "'");
    }

    static std::string at(const std::string& path, const std::string& key) {
        return path.empty() ? key : path + "." + key;
    }
    static std::string where(const std::string& path) { return path.empty() ? "(root)" : path; }

    bool valid(const Json& schema, const Json& v, const std::string& path) const {
        std::vector<std::string> e;
        check(schema, v, path, e);
        return e.empty();
    }

    void check(const Json& s, const Json& v, const std::string& path, std::vector<std::string>& errors) const {
        if (s.is_boolean()) {
            if (!s.get<bool>()) errors.push_back(where(path) + ": not allowed");
            return;
        }
        if (s.contains("$ref")) check(resolve(s["$ref"].get<std::string>()), v, path, errors);
        if (s.contains("type")) {
            const Json& t = s["type"];
            bool ok = false;
            if (t.is_string())
                ok = hasType(v, t.get<std::string>());
            else
                for (const Json& one : t) ok = ok || hasType(v, one.get<std::string>());
            if (!ok) {
                errors.push_back(where(path) + ": expected type " + t.dump() + ", got " + v.dump());
                return;
            }
        }
        if (s.contains("enum")) {
            bool ok = false;
            for (const Json& e : s["enum"]) ok = ok || e == v;
            if (!ok) errors.push_back(where(path) + ": " + v.dump() + " is not one of " + s["enum"].dump());
        }
        if (s.contains("const") && !(s["const"] == v))
            errors.push_back(where(path) + ": expected " + s["const"].dump() + ", got " + v.dump());
        if (v.is_number()) {
            const double d = v.get<double>();
            if (s.contains("minimum") && !(d >= s["minimum"].get<double>()))
                errors.push_back(where(path) + ": " + v.dump() + " < minimum " + s["minimum"].dump());
            if (s.contains("maximum") && !(d <= s["maximum"].get<double>()))
                errors.push_back(where(path) + ": " + v.dump() + " > maximum " + s["maximum"].dump());
            if (s.contains("exclusiveMinimum") && !(d > s["exclusiveMinimum"].get<double>()))
                errors.push_back(where(path) + ": " + v.dump() + " <= exclusive minimum " +
                                 s["exclusiveMinimum"].dump());
            if (s.contains("exclusiveMaximum") && !(d < s["exclusiveMaximum"].get<double>()))
                errors.push_back(where(path) + ": " + v.dump() + " >= exclusive maximum " +
                                 s["exclusiveMaximum"].dump());
        }
        if (v.is_string() && s.contains("minLength") && v.get<std::string>().size() < s["minLength"].get<std::size_t>())
            errors.push_back(where(path) + ": shorter than " + s["minLength"].dump());
        if (v.is_array()) {
            if (s.contains("minItems") && v.size() < s["minItems"].get<std::size_t>())
                errors.push_back(where(path) + ": fewer than " + s["minItems"].dump() + " items");
            if (s.contains("maxItems") && v.size() > s["maxItems"].get<std::size_t>())
                errors.push_back(where(path) + ": more than " + s["maxItems"].dump() + " items");
            if (s.contains("items"))
                for (std::size_t i = 0; i < v.size(); ++i)
                    check(s["items"], v[i], path + "[" + std::to_string(i) + "]", errors);
        }
        if (v.is_object()) {
            if (s.contains("minProperties") && v.size() < s["minProperties"].get<std::size_t>())
                errors.push_back(where(path) + ": fewer than " + s["minProperties"].dump() + " properties");
            if (s.contains("required"))
                for (const Json& key : s["required"])
                    if (!v.contains(key.get<std::string>()))
                        errors.push_back(at(path, key.get<std::string>()) + ": is required");
            const Json* props = s.contains("properties") ? &s["properties"] : nullptr;
            for (const auto& [key, value] : v.items()) {
                if (props && props->contains(key))
                    check((*props)[key], value, at(path, key), errors);
                else if (s.contains("additionalProperties"))
                    check(s["additionalProperties"], value, at(path, key), errors);
            }
        }
        if (s.contains("allOf"))
            for (const Json& sub : s["allOf"]) check(sub, v, path, errors);
        if (s.contains("anyOf")) {
            bool ok = false;
            for (const Json& sub : s["anyOf"]) ok = ok || valid(sub, v, path);
            if (!ok) errors.push_back(where(path) + ": matches none of the allowed forms");
        }
        if (s.contains("oneOf")) {
            int n = 0;
            for (const Json& sub : s["oneOf"]) n += valid(sub, v, path) ? 1 : 0;
            if (n != 1) errors.push_back(where(path) + ": matches " + std::to_string(n) + " forms, expected one");
        }
        if (s.contains("not") && valid(s["not"], v, path)) errors.push_back(where(path) + ": matches a forbidden form");
        if (s.contains("if")) {
            if (valid(s["if"], v, path)) {
                if (s.contains("then")) check(s["then"], v, path, errors);
            } else if (s.contains("else")) {
                check(s["else"], v, path, errors);
            }
        }
    }

    Json root_;
};

}  // namespace shadowlab::test
