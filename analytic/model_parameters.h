#pragma once
// One model's parameter values, whatever the model: a value of that model's
// own parameter struct (Deon2011Params, Chiang2016Params, ...) behind a
// type-erased holder, so that code outside analytic/ can carry, copy and
// store "a model's parameters" and reach their fields only through the
// model's parameter table (model_params.h) and the registry
// (model_registry.h). Inside analytic/, a model's code reads its own struct
// with as<P>().
#include <any>
#include <stdexcept>
#include <string>
#include <typeinfo>
#include <utility>

namespace fiberlab::analytic {

class ModelParameters {
 public:
  ModelParameters() = default;  // empty: holds no model's parameters
  template <class P>
  explicit ModelParameters(P value) : value_(std::move(value)) {}

  bool empty() const { return !value_.has_value(); }
  template <class P>
  bool holds() const {
    return std::any_cast<P>(&value_) != nullptr;
  }
  // The struct itself. Asking for another model's struct is a programming
  // error (the registry checks ownership before any table is applied):
  // std::logic_error.
  template <class P>
  P& as() {
    if (P* p = std::any_cast<P>(&value_)) return *p;
    throw std::logic_error(std::string("ModelParameters: not a ") + typeid(P).name());
  }
  template <class P>
  const P& as() const {
    if (const P* p = std::any_cast<P>(&value_)) return *p;
    throw std::logic_error(std::string("ModelParameters: not a ") + typeid(P).name());
  }

 private:
  std::any value_;
};

}  // namespace fiberlab::analytic
