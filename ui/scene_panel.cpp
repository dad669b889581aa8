#include "ui/scene_panel.hpp"

#include <QCheckBox>
#include <QComboBox>
#include <QDir>
#include <QFile>
#include <QFileInfo>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QPushButton>
#include <QScrollArea>
#include <QSplitter>
#include <QTabWidget>
#include <QVBoxLayout>

#include <fstream>
#include <set>
#include <sstream>

#include "core/errors.hpp"

namespace fl::ui {

using nlohmann::json;

namespace {

QString q(const std::string& s) { return QString::fromStdString(s); }

std::string numberText(double v) {
  std::ostringstream o;
  o.precision(10);
  o << v;
  return o.str();
}

QString rangeText(const SchemaField& f) {
  if (f.kind == "choice") {
    QStringList c;
    for (const auto& x : f.choices) c << q(x);
    return "one of {" + c.join(", ") + "}";
  }
  if (f.kind != "number" && f.kind != "integer" && f.kind != "number list") return {};
  auto bound = [](double v) { return std::abs(v) > 1e300 ? QString(v < 0 ? "-inf" : "inf") : QString::number(v, 'g', 6); };
  return QString("%1%2, %3%4")
      .arg(f.minOpen ? "(" : "[")
      .arg(bound(f.min))
      .arg(bound(f.max))
      .arg(f.maxOpen ? ")" : "]");
}

QString tooltipFor(const SchemaField& f) {
  QString t = "<b>" + q(f.key) + "</b>";
  if (!f.unit.empty() && f.unit != "-") t += " [" + q(f.unit) + "]";
  t += "<br>" + q(f.help).toHtmlEscaped();
  const QString range = rangeText(f);
  if (!range.isEmpty()) t += "<br><i>allowed:</i> " + range.toHtmlEscaped();
  t += "<br><i>default:</i> " + (f.defaultValue.empty() ? QString("none (required or optional)") : q(f.defaultValue));
  return t;
}

std::vector<std::string> stageTypes() {
  std::vector<std::string> t;
  for (const auto& f : sceneSchema())
    if (f.section.rfind("stage:", 0) == 0) {
      const std::string type = f.section.substr(6);
      if (std::find(t.begin(), t.end(), type) == t.end()) t.push_back(type);
    }
  return t;
}

}  // namespace

// ---------------------------------------------------------------- SchemaForm

SchemaForm::SchemaForm(const std::string& section, QWidget* parent) : QWidget(parent), m_section(section) {
  auto* form = new QFormLayout(this);
  form->setFieldGrowthPolicy(QFormLayout::AllNonFixedFieldsGrow);
  for (const auto& f : sceneSchema()) {
    if (f.section != section) continue;
    QWidget* w = nullptr;
    if (f.kind == "bool") {
      w = new QCheckBox(this);
    } else if (f.kind == "choice") {
      auto* c = new QComboBox(this);
      for (const auto& x : f.choices) c->addItem(q(x));
      w = c;
    } else {
      auto* e = new QLineEdit(this);
      e->setPlaceholderText(f.defaultValue.empty() ? tr("(unset)") : q(f.defaultValue));
      w = e;
    }
    w->setObjectName(q(section + "." + f.key));
    const QString tip = tooltipFor(f);
    w->setToolTip(tip);
    auto* label = new QLabel(q(f.key) + (f.unit.empty() || f.unit == "-" ? QString() : " [" + q(f.unit) + "]"), this);
    label->setToolTip(tip);
    form->addRow(label, w);
    m_fields.push_back({f, w});
  }
}

QWidget* SchemaForm::editor(const std::string& key) const {
  for (const auto& f : m_fields)
    if (f.schema.key == key) return f.widget;
  return nullptr;
}

void SchemaForm::setValues(const json& object) {
  for (auto& f : m_fields) {
    const bool has = object.is_object() && object.contains(f.schema.key) && !object.at(f.schema.key).is_null();
    const json v = has ? object.at(f.schema.key) : json();
    if (auto* c = qobject_cast<QCheckBox*>(f.widget)) {
      c->setChecked(has ? v.get<bool>() : f.schema.defaultValue == "true");
    } else if (auto* combo = qobject_cast<QComboBox*>(f.widget)) {
      combo->setCurrentText(q(has ? v.get<std::string>() : f.schema.defaultValue));
    } else if (auto* e = qobject_cast<QLineEdit*>(f.widget)) {
      if (!has) e->setText(q(f.schema.defaultValue));
      else if (v.is_string()) e->setText(q(v.get<std::string>()));
      else if (v.is_number_float()) e->setText(q(numberText(v.get<double>())));
      else if (v.is_array()) {
        QStringList parts;
        for (const auto& x : v) parts << q(x.is_number() ? numberText(x.get<double>()) : x.dump());
        e->setText(parts.join(", "));
      } else e->setText(q(v.dump()));
    }
  }
}

json SchemaForm::values() const {
  json o = json::object();
  for (const auto& f : m_fields) {
    const std::string name = (m_section.rfind("stage:", 0) == 0 ? "stage." : m_section + ".") + f.schema.key;
    if (auto* c = qobject_cast<QCheckBox*>(f.widget)) {
      o[f.schema.key] = c->isChecked();
    } else if (auto* combo = qobject_cast<QComboBox*>(f.widget)) {
      o[f.schema.key] = combo->currentText().toStdString();
    } else if (auto* e = qobject_cast<QLineEdit*>(f.widget)) {
      const QString text = e->text().trimmed();
      if (text.isEmpty()) {
        if (f.schema.kind == "string") o[f.schema.key] = "";
        continue;  // optional field left unset: the schema default (or "unchanged") applies
      }
      bool ok = true;
      if (f.schema.kind == "number") {
        o[f.schema.key] = text.toDouble(&ok);
      } else if (f.schema.kind == "integer") {
        const double d = text.toDouble(&ok);  // accepts 1e6 too
        ok = ok && d == static_cast<double>(static_cast<long long>(d));
        o[f.schema.key] = static_cast<long long>(d);
      } else if (f.schema.kind == "number list") {
        QString t = text;
        t.remove('[').remove(']');
        json arr = json::array();
        for (const QString& part : t.split(',', Qt::SkipEmptyParts)) {
          bool okPart = false;
          arr.push_back(part.trimmed().toDouble(&okPart));
          ok = ok && okPart;
        }
        o[f.schema.key] = arr;
      } else {
        o[f.schema.key] = text.toStdString();
      }
      if (!ok)
        throw InputError(name + " = '" + text.toStdString() + "' is not a valid " + f.schema.kind);
    }
  }
  return o;
}

// ---------------------------------------------------------------- ScenePanel

ScenePanel::ScenePanel(QWidget* parent) : QWidget(parent) {
  m_presets = new QListWidget(this);
  m_presets->setToolTip(tr("Preset scenes (resources/scenes). Double-click to load one, including the paper's runs."));
  connect(m_presets, &QListWidget::itemActivated, this,
          [this](QListWidgetItem* item) { loadFile(item->data(Qt::UserRole).toString()); });

  m_tabs = new QTabWidget(this);
  std::vector<std::string> sections;
  for (const auto& f : sceneSchema())
    if (f.section.rfind("stage:", 0) != 0 && std::find(sections.begin(), sections.end(), f.section) == sections.end())
      sections.push_back(f.section);
  for (const auto& s : sections) {
    auto* form = new SchemaForm(s, this);
    auto* scroll = new QScrollArea(this);
    scroll->setWidget(form);
    scroll->setWidgetResizable(true);
    m_tabs->addTab(scroll, q(s));
    m_sectionForms.push_back(form);
  }

  // stages
  auto* stagesPage = new QWidget(this);
  m_stageList = new QListWidget(stagesPage);
  m_stageList->setToolTip(tr("The loading protocol, run top to bottom."));
  m_newStageType = new QComboBox(stagesPage);
  m_stageType = new QComboBox(stagesPage);
  for (const auto& t : stageTypes()) {
    m_newStageType->addItem(q(t));
    m_stageType->addItem(q(t));
  }
  m_stageType->setToolTip(tr("Type of the selected stage; its fields follow the type."));
  auto* add = new QPushButton(tr("Add"), stagesPage);
  auto* remove = new QPushButton(tr("Remove"), stagesPage);
  auto* up = new QPushButton(tr("Up"), stagesPage);
  auto* down = new QPushButton(tr("Down"), stagesPage);
  add->setToolTip(tr("Append a stage of the chosen type."));
  connect(add, &QPushButton::clicked, this, [this] { addStage(m_newStageType->currentText()); });
  connect(remove, &QPushButton::clicked, this, [this] { removeStage(m_stageList->currentRow()); });
  connect(up, &QPushButton::clicked, this, [this] { moveStage(m_stageList->currentRow(), -1); });
  connect(down, &QPushButton::clicked, this, [this] { moveStage(m_stageList->currentRow(), +1); });
  connect(m_stageList, &QListWidget::currentRowChanged, this, [this](int row) {
    if (row == m_currentStage) return;
    try {
      commitStage();
    } catch (const std::exception& e) {
      emit errorRaised(QString::fromStdString(e.what()));
    }
    showStage(row);
  });
  connect(m_stageType, &QComboBox::textActivated, this, [this](const QString& type) {
    if (m_currentStage < 0) return;
    json& st = m_stages[static_cast<std::size_t>(m_currentStage)];
    // keep the name and the fields the new type shares; drop the rest
    json kept = m_stageForm ? m_stageForm->values() : json::object();
    st = json::object();
    st["type"] = type.toStdString();
    SchemaForm probe("stage:" + type.toStdString());
    for (auto it = kept.begin(); it != kept.end(); ++it)
      if (probe.editor(it.key())) st[it.key()] = it.value();
    const int row = m_currentStage;
    m_currentStage = -1;
    refreshStageList();
    m_stageList->setCurrentRow(row);
    showStage(row);
  });
  m_stageHolder = new QWidget(stagesPage);
  auto* holderLayout = new QVBoxLayout(m_stageHolder);
  holderLayout->setContentsMargins(0, 0, 0, 0);
  auto* buttons = new QHBoxLayout;
  buttons->addWidget(m_newStageType);
  buttons->addWidget(add);
  buttons->addWidget(remove);
  buttons->addWidget(up);
  buttons->addWidget(down);
  auto* typeRow = new QHBoxLayout;
  typeRow->addWidget(new QLabel(tr("type"), stagesPage));
  typeRow->addWidget(m_stageType, 1);
  auto* stagesLayout = new QVBoxLayout(stagesPage);
  stagesLayout->addWidget(m_stageList, 1);
  stagesLayout->addLayout(buttons);
  stagesLayout->addLayout(typeRow);
  auto* stageScroll = new QScrollArea(stagesPage);
  stageScroll->setWidget(m_stageHolder);
  stageScroll->setWidgetResizable(true);
  stagesLayout->addWidget(stageScroll, 2);
  m_tabs->insertTab(0, stagesPage, tr("stages"));
  m_tabs->setCurrentIndex(0);

  auto* applyButton = new QPushButton(tr("Apply (validate and load)"), this);
  applyButton->setToolTip(tr("Validate the edited scene against the schema and load it into the simulation."));
  connect(applyButton, &QPushButton::clicked, this, [this] { apply(); });

  auto* split = new QSplitter(Qt::Vertical, this);
  auto* top = new QWidget(this);
  auto* topLayout = new QVBoxLayout(top);
  topLayout->setContentsMargins(0, 0, 0, 0);
  topLayout->addWidget(new QLabel(tr("<b>Presets</b>"), top));
  topLayout->addWidget(m_presets);
  split->addWidget(top);
  split->addWidget(m_tabs);
  split->setStretchFactor(1, 3);
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(2, 2, 2, 2);
  layout->addWidget(split, 1);
  layout->addWidget(applyButton);
}

void ScenePanel::setPresetDirectory(const QString& directory) {
  m_presets->clear();
  const QDir dir(directory);
  for (const QFileInfo& info : dir.entryInfoList({"*.json"}, QDir::Files, QDir::Name)) {
    QString name = info.completeBaseName();
    try {
      std::ifstream in(info.absoluteFilePath().toStdString());
      const json j = json::parse(in, nullptr, true, true);
      if (j.contains("name") && j["name"].is_string()) name = q(j["name"].get<std::string>());
    } catch (const std::exception&) {
      // a broken preset is still listed; loading it shows the error
    }
    auto* item = new QListWidgetItem(name + "  (" + info.fileName() + ")", m_presets);
    item->setData(Qt::UserRole, info.absoluteFilePath());
    item->setToolTip(info.absoluteFilePath());
  }
}

int ScenePanel::presetCount() const { return m_presets->count(); }
QString ScenePanel::presetPath(int row) const { return m_presets->item(row)->data(Qt::UserRole).toString(); }

bool ScenePanel::loadFile(const QString& path) {
  try {
    const Scene scene = loadScene(path.toStdString());  // validates; errors name file and field
    setDocument(json::parse(sceneToJson(scene)), path);
    emit sceneApplied(scene);
    return true;
  } catch (const std::exception& e) {
    emit errorRaised(QString::fromStdString(e.what()));
    return false;
  }
}

void ScenePanel::setDocument(const json& doc, const QString& file) {
  m_file = file;
  for (SchemaForm* form : m_sectionForms) {
    if (form->section() == "scene") {
      json top = json::object();
      if (doc.contains("name")) top["name"] = doc["name"];
      form->setValues(top);
    } else {
      form->setValues(doc.value(form->section(), json::object()));
    }
  }
  m_stages = doc.value("stages", json::array());
  m_currentStage = -1;
  refreshStageList();
  if (stageCount() > 0) selectStage(0);
  else showStage(-1);
}

json ScenePanel::document() {
  commitStage();
  json doc = json::object();
  for (SchemaForm* form : m_sectionForms) {
    const json v = form->values();
    if (form->section() == "scene") {
      if (v.contains("name")) doc["name"] = v["name"];
    } else {
      doc[form->section()] = v;
    }
  }
  doc["stages"] = m_stages;
  return doc;
}

bool ScenePanel::apply() {
  try {
    const json doc = document();
    const QFileInfo info(m_file);
    const std::string source = m_file.isEmpty() ? "(edited scene)" : m_file.toStdString();
    const Scene scene = parseScene(doc, source, m_file.isEmpty() ? "" : info.absolutePath().toStdString());
    emit sceneApplied(scene);
    return true;
  } catch (const std::exception& e) {
    emit errorRaised(QString::fromStdString(e.what()));
    return false;
  }
}

bool ScenePanel::saveTo(const QString& path) {
  try {
    const QFileInfo info(m_file);
    Scene scene = parseScene(document(), path.toStdString(), m_file.isEmpty() ? "" : info.absolutePath().toStdString());
    std::ofstream out(path.toStdString());
    out << sceneToJson(scene) << "\n";
    if (!out) throw IoError(path.toStdString() + ": cannot write the scene");
    m_file = path;
    return true;
  } catch (const std::exception& e) {
    emit errorRaised(QString::fromStdString(e.what()));
    return false;
  }
}

int ScenePanel::stageCount() const { return static_cast<int>(m_stages.size()); }

void ScenePanel::commitStage() {
  if (m_currentStage < 0 || !m_stageForm || m_currentStage >= stageCount()) return;
  json v = m_stageForm->values();
  v["type"] = m_stageType->currentText().toStdString();
  m_stages[static_cast<std::size_t>(m_currentStage)] = v;
  if (auto* item = m_stageList->item(m_currentStage))
    item->setText(QString("%1. %2 (%3)").arg(m_currentStage + 1).arg(q(v.value("name", ""))).arg(q(v["type"])));
}

void ScenePanel::refreshStageList() {
  const QSignalBlocker block(m_stageList);
  m_stageList->clear();
  for (std::size_t i = 0; i < m_stages.size(); ++i) {
    const json& st = m_stages[i];
    m_stageList->addItem(QString("%1. %2 (%3)")
                             .arg(i + 1)
                             .arg(q(st.value("name", std::string())))
                             .arg(q(st.value("type", std::string()))));
  }
}

void ScenePanel::showStage(int row) {
  if (m_stageForm) {
    m_stageForm->deleteLater();
    m_stageForm->hide();
    m_stageForm = nullptr;
  }
  m_currentStage = row;
  if (row < 0 || row >= stageCount()) {
    m_currentStage = -1;
    return;
  }
  const json& st = m_stages[static_cast<std::size_t>(row)];
  const std::string type = st.value("type", std::string("isotropic_compression"));
  {
    const QSignalBlocker block(m_stageType);
    m_stageType->setCurrentText(q(type));
  }
  m_stageForm = new SchemaForm("stage:" + type, m_stageHolder);
  m_stageForm->setValues(st);
  m_stageHolder->layout()->addWidget(m_stageForm);
}

void ScenePanel::selectStage(int row) {
  m_stageList->setCurrentRow(row);
  if (m_currentStage != row) showStage(row);
}

void ScenePanel::addStage(const QString& type) {
  commitStage();
  json st = json::object();
  st["type"] = type.toStdString();
  st["name"] = type.toStdString();
  m_stages.push_back(st);
  m_currentStage = -1;
  refreshStageList();
  selectStage(stageCount() - 1);
}

void ScenePanel::removeStage(int row) {
  if (row < 0 || row >= stageCount()) return;
  m_currentStage = -1;  // the form being edited is discarded with its stage
  m_stages.erase(m_stages.begin() + row);
  refreshStageList();
  if (stageCount() > 0) selectStage(std::min(row, stageCount() - 1));
  else showStage(-1);
}

void ScenePanel::moveStage(int row, int delta) {
  const int to = row + delta;
  if (row < 0 || row >= stageCount() || to < 0 || to >= stageCount()) return;
  commitStage();
  std::swap(m_stages[static_cast<std::size_t>(row)], m_stages[static_cast<std::size_t>(to)]);
  m_currentStage = -1;
  refreshStageList();
  selectStage(to);
}

}  // namespace fl::ui
