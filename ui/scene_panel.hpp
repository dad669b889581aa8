/*
 * ScenePanel: the scene/protocol panel. Lists the preset scenes (resources/scenes, every .json, by name),
 * shows the scene as forms generated from sceneSchema() — one schema drives validation, these forms and the
 * reference document (house-style §17): a label "key [unit]", a tooltip with the help text, the default
 * and the allowed range — and the stage list (add, remove, reorder, edit a stage's fields; its form follows
 * the stage's type). The panel edits a JSON document; "Apply" validates it with parseScene() (whose errors
 * name the field) and emits the Scene.
 */
#pragma once

#include <QWidget>

#include <nlohmann/json.hpp>

#include <vector>

#include "core/scene.hpp"

class QComboBox;
class QFormLayout;
class QListWidget;
class QTabWidget;

namespace fl::ui {

// A form for one schema section (a JSON object).
class SchemaForm : public QWidget {
  Q_OBJECT

 public:
  SchemaForm(const std::string& section, QWidget* parent = nullptr);
  void setValues(const nlohmann::json& object);
  // Throws InputError naming "section.key" when a field cannot be read as its kind.
  nlohmann::json values() const;
  const std::string& section() const { return m_section; }
  QWidget* editor(const std::string& key) const;  // nullptr if absent

 private:
  struct Field {
    SchemaField schema;
    QWidget* widget = nullptr;
  };
  std::string m_section;
  std::vector<Field> m_fields;
};

class ScenePanel : public QWidget {
  Q_OBJECT

 public:
  explicit ScenePanel(QWidget* parent = nullptr);

  // Presets: every *.json in `directory`, listed by scene name.
  void setPresetDirectory(const QString& directory);
  int presetCount() const;
  QString presetPath(int row) const;

  // Loads and validates a scene file; on error emits errorRaised (with the file and field) and returns false.
  bool loadFile(const QString& path);
  void setDocument(const nlohmann::json& doc, const QString& file);
  // The edited document (the stage being edited included); throws InputError on unreadable fields.
  nlohmann::json document();
  // Validates the edited document with parseScene; emits sceneApplied or errorRaised.
  bool apply();
  bool saveTo(const QString& path);
  QString currentFile() const { return m_file; }

  // Stage list editing (also reachable from the buttons).
  int stageCount() const;
  void addStage(const QString& type);
  void removeStage(int row);
  void moveStage(int row, int delta);
  void selectStage(int row);
  SchemaForm* stageForm() const { return m_stageForm; }

 signals:
  void sceneApplied(const fl::Scene& scene);
  void errorRaised(const QString& message);

 private:
  void commitStage();
  void showStage(int row);
  void refreshStageList();

  QListWidget* m_presets = nullptr;
  QTabWidget* m_tabs = nullptr;
  std::vector<SchemaForm*> m_sectionForms;
  QListWidget* m_stageList = nullptr;
  QComboBox* m_stageType = nullptr;
  QComboBox* m_newStageType = nullptr;
  QFormLayout* m_stageBox = nullptr;
  QWidget* m_stageHolder = nullptr;
  SchemaForm* m_stageForm = nullptr;
  nlohmann::json m_stages = nlohmann::json::array();
  int m_currentStage = -1;
  QString m_file;
};

}  // namespace fl::ui
